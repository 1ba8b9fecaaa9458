// Rest test by motion (rest_test.hpp): a body rests while its centre and
// surface points stay in small balls, whatever its velocity of the moment.
#include "rest_test.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace stc {
namespace {

constexpr double kDt = 1.0 / 60.0;
constexpr double kWindow = 0.5;                   // s (SleepOptions::time_to_sleep)
constexpr double kSpeed = 0.02;                   // m/s (SleepOptions::linear_speed)
constexpr double kRadius = 0.5 * kSpeed * kWindow;  // what Islands asks

Pose at(const Vec3& position, const Quat& orientation = Quat::Identity()) {
  Pose p;
  p.position = position;
  p.orientation = orientation;
  return p;
}

// The longest time (s) the body counted as resting without a break, over
// `seconds` of poses pose(t), one a tick: what a rest timer would reach.
template <class PoseAt>
double longestRest(RestTest& test, double seconds, PoseAt pose) {
  int run = 0, longest = 0;
  const int ticks = static_cast<int>(std::lround(seconds / kDt));
  for (int k = 0; k < ticks; ++k) {
    run = test.update(0, pose(k * kDt), kDt, kWindow, kRadius) ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  return longest * kDt;
}

TEST(RestTest, StillBodyRests) {
  RestTest test;
  test.add(0.2);
  EXPECT_NEAR(longestRest(test, 3.0, [](double) { return at(Vec3(1.0, 2.0, 3.0)); }), 3.0, 1e-9);
}

TEST(RestTest, CreepSlowerThanTheSpeedRestsHoweverLongAndFasterDoesNot) {
  RestTest slow, fast;
  slow.add(0.2);
  fast.add(0.2);
  // Over 10 s, 20 windows: the slow body rests all along, the fast one never
  // for a whole window.
  EXPECT_NEAR(longestRest(slow, 10.0, [](double t) { return at(Vec3(0.9 * kSpeed * t, 0.0, 0.0)); }), 10.0, 1e-9);
  EXPECT_LT(longestRest(fast, 10.0, [](double t) { return at(Vec3(1.2 * kSpeed * t, 0.0, 0.0)); }), kWindow);
}

TEST(RestTest, RockingInPlaceRestsAlthoughItsSpinIsFast) {
  // A rock rocking to and fro: 1 rad/s peak spin (ten times the old 0.1 rad/s
  // threshold), 2 mm peak travel at its reach.
  RestTest test;
  const double reach = 0.25, amplitude = 0.002 / reach;  // rad
  const double omega = 1.0 / amplitude;                  // rad/s of the rocking: peak spin 1 rad/s
  test.add(reach);
  const auto rocking = [&](double t) {
    return at(Vec3::Zero(), Quat(Eigen::AngleAxisd(amplitude * std::sin(omega * t), Vec3::UnitZ())));
  };
  EXPECT_NEAR(longestRest(test, 5.0, rocking), 5.0, 1e-9);
}

TEST(RestTest, SpinIsJudgedByTheSurfaceSpeedItGives) {
  // The same slow spin: a pebble's surface moves at 0.1 reach * w, a boulder's at 10 x that.
  const double w = 0.5 * kSpeed / 0.1;  // a 0.1 m reach turns at half the speed limit
  RestTest pebble, boulder;
  pebble.add(0.1);
  boulder.add(1.0);
  const auto spin = [&](double t) { return at(Vec3::Zero(), Quat(Eigen::AngleAxisd(w * t, Vec3::UnitZ()))); };
  EXPECT_NEAR(longestRest(pebble, 3.0, spin), 3.0, 1e-9);
  EXPECT_LT(longestRest(boulder, 3.0, spin), kWindow);
}

TEST(RestTest, AJumpRestartsTheTestAndRestartStartsAfresh) {
  RestTest test;
  test.add(0.2);
  EXPECT_TRUE(test.update(0, at(Vec3::Zero()), kDt, kWindow, kRadius));
  EXPECT_TRUE(test.update(0, at(Vec3(0.004, 0.0, 0.0)), kDt, kWindow, kRadius));  // 2 mm ball
  EXPECT_FALSE(test.update(0, at(Vec3(0.05, 0.0, 0.0)), kDt, kWindow, kRadius));  // moved: restarts here
  EXPECT_TRUE(test.update(0, at(Vec3(0.052, 0.0, 0.0)), kDt, kWindow, kRadius));
  test.restart(0);  // e.g. woken: the next pose is a fresh start, wherever it is
  EXPECT_TRUE(test.update(0, at(Vec3(3.0, 0.0, 0.0)), kDt, kWindow, kRadius));
  EXPECT_FALSE(test.update(0, at(Vec3(3.1, 0.0, 0.0)), kDt, kWindow, kRadius));
}

TEST(RestTest, RemoveMovesTheLastBodyIntoTheGap) {
  RestTest test;
  test.add(0.2);
  test.add(5.0);
  test.update(1, at(Vec3::Zero()), kDt, kWindow, kRadius);
  test.remove(0, 1);
  // Body 1 (reach 5 m) is now body 0, with its ball: a 0.01 rad turn moves its reach 5 cm.
  EXPECT_FALSE(test.update(0, at(Vec3::Zero(), Quat(Eigen::AngleAxisd(0.01, Vec3::UnitZ()))), kDt, kWindow, kRadius));
}

}  // namespace
}  // namespace stc
