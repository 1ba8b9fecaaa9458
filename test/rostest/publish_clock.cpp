// ~publish_clock, ~entities, ~entity_states and contact names, judged by stamps:
// physics time is ticks x dt from 0, and every message of a tick carries it.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <rosgraph_msgs/Clock.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/EntityList.h>
#include <sphere_tree_collision/EntityStates.h>
#include <sphere_tree_collision/Spawn.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <cmath>
#include <map>
#include <set>

namespace {

using stc_test::Recorder;

constexpr double kDt = 1.0 / 30.0;
constexpr double kDrift = 0.5;  // m/s along x: the drifter of services_scene.yaml, from x = 0

class PublishClock : public testing::Test {
 protected:
  PublishClock()
      : clock_(nh_, "/clock", 1000),
        stats_(nh_, "/collision_world/tick_stats", 1000),
        contacts_(nh_, "/collision_world/contacts", 1000),
        states_(nh_, "/collision_world/entity_states", 1000),
        list_(nh_, "/collision_world/entities"),
        listener_(tf_, nh_, false) {
    clock_.keep_all = stats_.keep_all = contacts_.keep_all = states_.keep_all = true;
    EXPECT_TRUE(list_.waitFor(1, stc_test::kLivenessSeconds));
  }

  std::set<std::uint64_t> clockTimes() const {
    std::set<std::uint64_t> out;
    for (const auto& c : clock_.all) out.insert(c.clock.toNSec());
    return out;
  }
  // Whether `stamp` is a clock time the test had the chance to hear: the
  // topics connect one by one, so a tick before /clock's link came up (or
  // whose /clock is still on its way) is not judged.
  static bool heard(const std::set<std::uint64_t>& clock, const ros::Time& stamp) {
    return !clock.empty() && stamp.toNSec() >= *clock.begin() && stamp.toNSec() <= *clock.rbegin();
  }
  // 1 when `stamp` is one of the clock times heard (or could not have been heard).
  static std::size_t onClock(const std::set<std::uint64_t>& clock, const ros::Time& stamp) {
    return heard(clock, stamp) ? clock.count(stamp.toNSec()) : 1u;
  }
  std::map<std::uint32_t, std::string> framesById() const {
    std::map<std::uint32_t, std::string> out;
    for (const auto& e : list_.last.entities) out[e.id] = e.frame;
    return out;
  }

  ros::NodeHandle nh_;
  Recorder<rosgraph_msgs::Clock> clock_;
  Recorder<sphere_tree_collision::TickStats> stats_;
  Recorder<sphere_tree_collision::ContactArray> contacts_;
  Recorder<sphere_tree_collision::EntityStates> states_;
  Recorder<sphere_tree_collision::EntityList> list_;
  tf2_ros::Buffer tf_;
  tf2_ros::TransformListener listener_;
};

TEST_F(PublishClock, EveryMessageOfATickCarriesItsClockTime) {
  // Two touching cubes, so contacts flow (response is off: they stay).
  for (double x : {5.0, 5.15}) {
    sphere_tree_collision::Spawn s;
    s.request.entity.name = x < 5.1 ? "touch_a" : "touch_b";
    s.request.entity.preset = "cube";
    s.request.entity.resolution = 4;
    s.request.entity.voxel_size = 0.05;
    s.request.entity.pose.position.x = x;
    s.request.entity.pose.orientation.w = 1.0;
    s.request.entity.density = 1000.0;
    ASSERT_TRUE(ros::service::call("/collision_world/spawn", s));
    ASSERT_TRUE(s.response.success) << s.response.message;
  }
  ASSERT_TRUE(stc_test::spinUntil([&] { return list_.last.entities.size() == 4 && contacts_.count() >= 20 && stats_.count() >= 40; },
                                  stc_test::kLivenessSeconds));
  const std::set<std::uint64_t> clock = clockTimes();
  ASSERT_FALSE(clock.empty());

  std::uint64_t previous = 0;
  std::size_t judged = 0;
  for (const auto& s : stats_.all) {
    judged += heard(clock, s.header.stamp) ? 1 : 0;
    EXPECT_EQ(onClock(clock, s.header.stamp), 1u) << "tick " << s.tick << " stamp " << s.header.stamp;
    EXPECT_NEAR(s.physics_time, s.tick * kDt, 1e-9 * s.tick);
    EXPECT_NEAR(s.header.stamp.toSec(), s.physics_time, 1e-9);
    EXPECT_GT(s.tick, previous);
    previous = s.tick;
    if (s.tick > 2) {
      EXPECT_GT(s.real_time_factor, 0.0);
      EXPECT_TRUE(std::isfinite(s.real_time_factor));
    }
  }

  EXPECT_GE(judged, stats_.all.size() / 2) << "most ticks fall within the clock times heard";

  const auto frames = framesById();
  std::size_t named_contacts = 0;
  for (const auto& array : contacts_.all) {
    EXPECT_EQ(onClock(clock, array.header.stamp), 1u) << array.header.stamp;
    for (const auto& c : array.contacts) {
      EXPECT_EQ(c.name_a, frames.at(c.entity_a));
      EXPECT_EQ(c.name_b, frames.at(c.entity_b));
      named_contacts += (c.name_a == "touch_a" || c.name_b == "touch_a") ? 1 : 0;
    }
  }
  EXPECT_GT(named_contacts, 0u);
}

TEST_F(PublishClock, EntityStatesAgreeWithPhysicsTimeAndTf) {
  ASSERT_TRUE(stc_test::spinUntil([&] { return states_.count() >= 30; }, stc_test::kLivenessSeconds));
  const std::set<std::uint64_t> clock = clockTimes();
  const auto frames = framesById();
  for (const auto& m : states_.all) {
    ASSERT_EQ(m.names.size(), m.ids.size());
    ASSERT_EQ(m.poses.size(), m.ids.size());
    ASSERT_EQ(m.twists.size(), m.ids.size());
    EXPECT_EQ(m.header.frame_id, "world");
    EXPECT_EQ(onClock(clock, m.header.stamp), 1u) << m.header.stamp;
    bool found = false;
    for (std::size_t i = 0; i < m.ids.size(); ++i) {
      EXPECT_EQ(m.names[i], frames.at(m.ids[i]));
      if (m.names[i] != "drifter") continue;
      found = true;
      // x = v t exactly (no gravity, no contact): the stamp is the physics time.
      EXPECT_NEAR(m.poses[i].position.x, kDrift * m.header.stamp.toSec(), 1e-6) << m.header.stamp;
      EXPECT_NEAR(m.poses[i].position.z, 2.0, 1e-12);
      EXPECT_NEAR(m.twists[i].linear.x, kDrift, 1e-12);
      EXPECT_NEAR(m.twists[i].angular.z, 0.0, 1e-12);
    }
    EXPECT_TRUE(found);
  }
  // tf at a state's stamp shows the same pose.
  const auto& last = states_.all.back();
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf_.canTransform("world", "drifter", last.header.stamp); }, stc_test::kLivenessSeconds));
  const auto t = tf_.lookupTransform("world", "drifter", last.header.stamp);
  for (std::size_t i = 0; i < last.ids.size(); ++i) {
    if (last.names[i] != "drifter") continue;
    EXPECT_DOUBLE_EQ(t.transform.translation.x, last.poses[i].position.x);
    EXPECT_DOUBLE_EQ(t.transform.translation.z, last.poses[i].position.z);
  }
  // The list names the scene's entities with their shapes and static flags.
  bool floor_static = false, drifter_moving = false;
  for (const auto& e : list_.last.entities) {
    floor_static |= e.name == "floor" && e.is_static && e.shape.rfind("plate/", 0) == 0;
    drifter_moving |= e.name == "drifter" && !e.is_static && e.shape.rfind("sphere/", 0) == 0;
  }
  EXPECT_TRUE(floor_static);
  EXPECT_TRUE(drifter_moving);
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "publish_clock_test"); }
