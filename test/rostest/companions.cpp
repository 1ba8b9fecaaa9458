// Companion nodes: gaze_simulator's five modes put the gaze where they say,
// and rockfall_spawner drops valid rocks at its rate, keeping at most
// max_rocks alive (oldest despawned first).
#include "rostest_util.hpp"

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/ros/conversions.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/EntityStates.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <cmath>
#include <map>
#include <set>

namespace {

using sphere_tree_collision::GazePoint;
using stc_test::Recorder;

constexpr double kWidth = 1280, kHeight = 720;  // the world node's default image

bool onImage(const GazePoint& g) { return g.x >= 0 && g.y >= 0 && g.x <= kWidth && g.y <= kHeight; }

// Seconds between the stamps of the first and the last message recorded.
double stampSpan(const std::vector<GazePoint>& all) {
  return all.size() < 2 ? 0.0 : (all.back().header.stamp - all.front().header.stamp).toSec();
}

// Records until the messages' own stamps span `seconds`. The wall-clock bound
// is only a liveness guard: what is asserted comes from stamps and content.
bool recordSpan(Recorder<GazePoint>& gaze, double seconds) {
  return stc_test::spinUntil([&] { return stampSpan(gaze.all) >= seconds; }, stc_test::kLivenessSeconds);
}

// The node's perception camera as tf has it (the simulators project with it).
stc::Perception perceptionFromTf(const tf2_ros::Buffer& tf) {
  const auto cam = tf.lookupTransform("world", "perception_camera", ros::Time(0));
  stc::Camera camera;
  camera.camera_to_world.position = stc_ros::toEigen(cam.transform.translation);
  camera.camera_to_world.orientation = stc_ros::toEigen(cam.transform.rotation).normalized();
  stc::Perception perception;
  perception.setCamera(camera);
  return perception;
}

TEST(Companions, FixedGazeStaysOnItsPixel) {
  ros::NodeHandle nh;
  Recorder<GazePoint> gaze(nh, "/fixed/gaze");
  gaze.keep_all = true;
  ASSERT_TRUE(gaze.waitFor(10, stc_test::kLivenessSeconds));
  for (std::size_t i = 0; i < gaze.all.size(); ++i) {
    EXPECT_DOUBLE_EQ(gaze.all[i].x, 100.0);
    EXPECT_DOUBLE_EQ(gaze.all[i].y, 200.0);
    if (i > 0) EXPECT_GT(gaze.all[i].header.stamp, gaze.all[i - 1].header.stamp) << "stamps advance";
  }
}

// The circle's angle is a function of the stamp: a(t) = a0 + 2 pi t / period.
// Over a span of stamps longer than one period, every message lies on the
// circle at the angle its stamp says, so the gaze went once round the centre,
// however many messages the machine's load let through.
TEST(Companions, CircleGazeGoesRoundTheCentre) {
  constexpr double kPeriod = 2.0, kRadius = 150.0;  // circle.test's parameters
  ros::NodeHandle nh;
  Recorder<GazePoint> gaze(nh, "/circle/gaze");
  gaze.keep_all = true;
  ASSERT_TRUE(recordSpan(gaze, 1.2 * kPeriod));
  ASSERT_GE(gaze.all.size(), 2u);
  const auto angle = [](const GazePoint& g) { return std::atan2(g.y - 0.5 * kHeight, g.x - 0.5 * kWidth); };
  const GazePoint& first = gaze.all.front();
  for (const GazePoint& g : gaze.all) {
    EXPECT_NEAR(std::hypot(g.x - 0.5 * kWidth, g.y - 0.5 * kHeight), kRadius, 1e-6);
    const double turned = 2.0 * M_PI * (g.header.stamp - first.header.stamp).toSec() / kPeriod;
    const double off = std::remainder(angle(g) - angle(first) - turned, 2.0 * M_PI);
    EXPECT_NEAR(off, 0.0, 1e-6) << "angle not the one its stamp says, " << turned << " rad after the first";
  }
  EXPECT_GE(stampSpan(gaze.all), kPeriod) << "the checked messages cover a whole turn";
}

// Saccades: the target is fixed within each 0.2 s period and jumps between
// periods. Judged by stamps: messages on one target span less than a period,
// and messages at least a period apart are on different targets.
TEST(Companions, SaccadesJumpBetweenPixelsOnTheImage) {
  constexpr double kPeriod = 0.2;  // saccades' ~saccade_period in the .test
  ros::NodeHandle nh;
  Recorder<GazePoint> gaze(nh, "/saccades/gaze");
  gaze.keep_all = true;
  // A chain of messages each at least a period after the last.
  const auto chainOf = [&] {
    std::vector<const GazePoint*> chain;
    for (const auto& g : gaze.all) {
      if (chain.empty() || g.header.stamp >= chain.back()->header.stamp + ros::Duration(kPeriod)) chain.push_back(&g);
    }
    return chain;
  };
  // Until the stamps span 6 periods and hold 4 links (a starved simulator
  // leaves longer gaps: it is recorded for longer, not judged by them).
  ASSERT_TRUE(stc_test::spinUntil([&] { return stampSpan(gaze.all) >= 6 * kPeriod && chainOf().size() >= 4; },
                                  stc_test::kLivenessSeconds));
  std::map<std::pair<double, double>, std::pair<ros::Time, ros::Time>> on_target;  // first and last stamp
  for (const auto& g : gaze.all) {
    EXPECT_TRUE(onImage(g)) << g.x << ", " << g.y;
    auto [it, added] = on_target.try_emplace({g.x, g.y}, g.header.stamp, g.header.stamp);
    it->second.second = g.header.stamp;
  }
  for (const auto& [pixel, stamps] : on_target) {
    EXPECT_LT((stamps.second - stamps.first).toSec(), kPeriod + 1e-6) << "rests one period on a target";
  }
  // The chain's messages are all on different targets.
  const std::vector<const GazePoint*> links = chainOf();
  std::set<std::pair<double, double>> targets;
  for (const GazePoint* g : links) targets.insert({g->x, g->y});
  EXPECT_EQ(targets.size(), links.size()) << "the gaze jumps every period";
}

TEST(Companions, FollowGazeTracksTheEntitysProjection) {
  ros::NodeHandle nh;
  tf2_ros::Buffer tf;
  tf2_ros::TransformListener listener(tf, nh, false);
  ros::Publisher spawn = nh.advertise<sphere_tree_collision::SpawnEntity>("/collision_world/spawn", 10);
  ASSERT_TRUE(stc_test::spinUntil([&] { return spawn.getNumSubscribers() > 0; }, stc_test::kLivenessSeconds));
  sphere_tree_collision::SpawnEntity probe;
  probe.name = "probe";
  probe.preset = "cube";
  probe.voxel_size = 0.05;
  probe.pose.position.x = 0.6;
  probe.pose.position.z = 0.8;
  probe.pose.orientation.w = 1.0;
  probe.twist.linear.x = -0.2;  // it moves: the gaze follows
  probe.density = 1000.0;
  probe.restitution = 0.3;
  probe.friction = 0.5;
  spawn.publish(probe);

  Recorder<GazePoint> gaze(nh, "/follow/gaze");
  ASSERT_TRUE(gaze.waitFor(1, stc_test::kLivenessSeconds));
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return tf.canTransform("world", "probe", ros::Time(0)) && tf.canTransform("world", "perception_camera", ros::Time(0)); },
      stc_test::kLivenessSeconds));
  const stc::Perception perception = perceptionFromTf(tf);
  // The simulator stamps each gaze with the tf stamp of the probe pose it
  // projected: the probe's pose at that stamp must project onto the gaze.
  gaze.keep_all = true;
  gaze.clear();
  int checked = 0;
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        while (checked < 10 && !gaze.all.empty()) {  // two may come in one spin
          const GazePoint g = gaze.all.front();
          gaze.all.erase(gaze.all.begin());
          if (!tf.canTransform("world", "probe", g.header.stamp)) continue;  // not yet in our buffer
          const auto at = tf.lookupTransform("world", "probe", g.header.stamp);
          const auto pixel = perception.project(stc_ros::toEigen(at.transform.translation));
          EXPECT_TRUE(pixel.has_value());
          if (!pixel) continue;
          EXPECT_NEAR(g.x, pixel->x(), 1e-3);
          EXPECT_NEAR(g.y, pixel->y(), 1e-3);
          ++checked;
        }
        return checked >= 10;
      },
      stc_test::kLivenessSeconds));
}

// Active: the gaze is on an entity on the image (the fastest, by the node), where the
// latest entity_states (moved on at its velocity to the gaze's stamp) puts it.
// The rockfall spawner's rocks fall in front of the camera: something moves.
TEST(Companions, ActiveGazeIsOnAnEntityOnTheImage) {
  ros::NodeHandle nh;
  tf2_ros::Buffer tf;
  tf2_ros::TransformListener listener(tf, nh, false);
  Recorder<sphere_tree_collision::EntityStates> states(nh, "/collision_world/entity_states", 1);
  Recorder<GazePoint> gaze(nh, "/active/gaze");
  ASSERT_TRUE(gaze.waitFor(1, stc_test::kLivenessSeconds)) << "no active gaze: nothing moved on the image?";
  ASSERT_TRUE(states.waitFor(1, stc_test::kLivenessSeconds));
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf.canTransform("world", "perception_camera", ros::Time(0)); },
                                  stc_test::kLivenessSeconds));
  const stc::Perception perception = perceptionFromTf(tf);
  // Near some entity's projection (the simulator may have used the states
  // message before or after ours: a falling rock moves a few pixels between).
  constexpr double kNearPixels = 60.0;
  int checked = 0, near = 0;
  gaze.keep_all = true;
  gaze.clear();
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        while (checked < 20 && !gaze.all.empty()) {
          const GazePoint g = gaze.all.front();
          gaze.all.erase(gaze.all.begin());
          EXPECT_TRUE(onImage(g)) << g.x << ", " << g.y;
          const auto& m = states.last;
          const double ahead = std::max(0.0, (g.header.stamp - m.header.stamp).toSec());
          double best = 1e9;
          for (std::size_t i = 0; i < m.poses.size(); ++i) {
            const auto& v = m.twists[i].linear;
            const stc::Vec3 at = stc_ros::toEigen(m.poses[i].position) + ahead * stc::Vec3(v.x, v.y, v.z);
            if (const auto pixel = perception.project(at)) best = std::min(best, std::hypot(g.x - pixel->x(), g.y - pixel->y()));
          }
          near += best < kNearPixels;
          ++checked;
        }
        return checked >= 20;
      },
      stc_test::kLivenessSeconds));
  EXPECT_GE(near, 16) << "of 20 active gazes, " << near << " within " << kNearPixels << " px of an entity";
}

TEST(Companions, RockfallDropsValidRocksAndKeepsAtMostMaxRocks) {
  ros::NodeHandle nh;
  Recorder<sphere_tree_collision::SpawnEntity> spawns(nh, "/collision_world/spawn");
  Recorder<sphere_tree_collision::Despawn> despawns(nh, "/collision_world/despawn");
  Recorder<sphere_tree_collision::TickStats> stats(nh, "/collision_world/tick_stats");
  spawns.keep_all = true;
  despawns.keep_all = true;
  ASSERT_TRUE(spawns.waitFor(8, stc_test::kLivenessSeconds));
  for (const auto& s : spawns.all) {
    EXPECT_EQ(s.preset, "rock");
    EXPECT_GE(s.pose.position.z, 1.0);
    EXPECT_LE(s.pose.position.z, 2.0);
  }
  // Oldest first: the k-th despawn removes rock_<k>.
  ASSERT_FALSE(despawns.all.empty());
  const std::string first = spawns.all.front().name;  // the spawner's numbering may have started before us
  const long first_index = std::stol(first.substr(first.rfind('_') + 1));
  for (std::size_t k = 0; k < despawns.all.size(); ++k) {
    const std::string& name = despawns.all[k].name;
    const long index = std::stol(name.substr(name.rfind('_') + 1));
    if (k > 0) {
      const std::string& prev = despawns.all[k - 1].name;
      EXPECT_EQ(index, std::stol(prev.substr(prev.rfind('_') + 1)) + 1) << "despawned in spawn order";
    }
    EXPECT_LT(index, first_index + static_cast<long>(spawns.all.size()));
  }
  // The world accepted them all and holds at most 3 rocks (+ the follow probe).
  ASSERT_TRUE(stats.waitFor(1, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats.last.rejected_spawn, 0u) << stats.last.last_rejection;
  EXPECT_LE(stats.last.entities, 4u);
  EXPECT_GE(stats.last.entities, 3u);
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "companions_test"); }
