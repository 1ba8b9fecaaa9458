// Smoke test: the node publishes what it advertises: tick_stats and contacts
// every tick, markers every ~rate / ~marker_rate ticks (judged by the stamps
// and tick numbers the messages carry, never by arrival rates).
#include "rostest_util.hpp"
#include "sphere_tree_collision/ros/tick_budget_rule.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>

namespace {

using stc_test::Recorder;
using visualization_msgs::Marker;

double param(const std::string& name) {
  double v = 0.0;
  EXPECT_TRUE(ros::param::get("~" + name, v)) << "test parameter ~" << name << " missing";
  return v;
}

std::vector<std::string> entityFrames() {
  std::vector<std::string> frames;
  EXPECT_TRUE(ros::param::get("~entity_frames", frames));
  return frames;
}

// Stamp of every tick_stats message seen, by tick number.
struct TickStamps {
  explicit TickStamps(ros::NodeHandle& nh) : stats(nh, "/collision_world/tick_stats", 1000) { stats.keep_all = true; }
  std::optional<std::uint64_t> tickAt(const ros::Time& stamp) const {
    for (const auto& s : stats.all) {
      if (s.header.stamp == stamp) return s.tick;
    }
    return std::nullopt;
  }
  Recorder<sphere_tree_collision::TickStats> stats;
};

TEST(Smoke, AdvertisedTypes) {
  ros::NodeHandle nh;
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"/collision_world/markers", "visualization_msgs/MarkerArray"},
      {"/collision_world/tick_stats", "sphere_tree_collision/TickStats"},
      {"/collision_world/contacts", "sphere_tree_collision/ContactArray"},
      {"/tf", "tf2_msgs/TFMessage"}};
  // The node advertises them one after the other at start-up: wait for all.
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        for (const auto& [topic, type] : expected) {
          if (stc_test::topicType(topic).empty()) return false;
        }
        return true;
      },
      stc_test::kLivenessSeconds));
  for (const auto& [topic, type] : expected) EXPECT_EQ(stc_test::topicType(topic), type) << topic;
}

TEST(Smoke, MarkersEveryFewTicks) {
  ros::NodeHandle nh;
  const auto ticks_per_marker = static_cast<std::uint64_t>(std::lround(param("tick_rate") / param("marker_rate")));
  stc_test::MarkerState state(nh, "/collision_world/markers");
  TickStamps ticks(nh);
  Recorder<visualization_msgs::MarkerArray> markers(nh, "/collision_world/markers", 1000);
  markers.keep_all = true;
  // A gaze puts a stamped marker in every array (entity geometry is
  // frame-locked and carries no stamp).
  ros::Publisher gaze = nh.advertise<sphere_tree_collision::GazePoint>("/collision_world/gaze", 10);
  ros::SteadyTimer gazer = nh.createSteadyTimer(ros::WallDuration(0.05), [&](const ros::SteadyTimerEvent&) {
    sphere_tree_collision::GazePoint g;  // stamp 0: "now" to the node, never stale however late it arrives
    g.x = 640;
    g.y = 360;
    gaze.publish(g);
  });
  // Each marker array carries the stamp of the tick whose state it shows; that
  // tick's number is a multiple of ~rate / ~marker_rate.
  std::size_t matched = 0;
  std::size_t next = 0;
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        for (; next < markers.all.size(); ++next) {
          const auto& array = markers.all[next];
          if (array.markers.empty()) continue;  // carries no stamp
          ros::Time stamp;  // the tick's (DELETE markers may carry none)
          for (const Marker& m : array.markers) stamp = std::max(stamp, m.header.stamp);
          for (const Marker& m : array.markers) {
            if (m.action == Marker::ADD && !m.frame_locked) EXPECT_EQ(m.header.stamp, stamp) << m.ns;
          }
          const auto tick = ticks.tickAt(stamp);
          if (!tick) continue;  // that tick's stats not seen (yet)
          EXPECT_EQ(*tick % ticks_per_marker, 0u) << "markers of tick " << *tick;
          ++matched;
        }
        return matched >= 3;
      },
      stc_test::kLivenessSeconds));
  gazer.stop();

  // A new subscriber first gets the whole scene, DELETEALL first.
  const auto& first = state.first.markers;
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.front().action, Marker::DELETEALL) << "a snapshot starts from a clean slate";

  // What rviz holds: every entity's voxels and the configured tree levels,
  // frame-locked in the entity's tf frame (incremental mode, the default).
  const std::vector<std::string> frames = entityFrames();
  const std::set<std::string> frame_set(frames.begin(), frames.end());
  EXPECT_EQ(state.count("voxels"), static_cast<int>(frames.size())) << "one CUBE_LIST per entity";
  EXPECT_GT(state.count("tree_level_1"), 0);
  EXPECT_GT(state.count("tree_level_2"), 0);
  EXPECT_EQ(state.count("tree_level_0"), 0) << "only the levels of ~marker_levels";
  EXPECT_EQ(state.count("tree_level_3"), 0);
  for (const auto& [key, m] : state.markers) {
    if (key.first != "gaze") EXPECT_FALSE(m.points.empty()) << key.first << "/" << key.second;  // gaze: one SPHERE
    if (key.first == "voxels" || key.first.rfind("tree_level_", 0) == 0) {
      EXPECT_TRUE(m.frame_locked) << key.first << "/" << key.second;
      EXPECT_EQ(frame_set.count(m.header.frame_id), 1u) << "in an entity frame, not " << m.header.frame_id;
    }
    if (m.type == Marker::SPHERE_LIST) {
      EXPECT_GT(m.scale.x, 0.0);
      EXPECT_EQ(m.scale.x, m.scale.y);
      EXPECT_EQ(m.scale.x, m.scale.z);
      if (key.first != "contacts") EXPECT_LT(m.color.a, 1.0f) << "tree levels are semi-transparent";
    }
  }
  // Unique (ns, id) within the snapshot: rviz would warn and drop duplicates.
  std::set<std::pair<std::string, int>> ids;
  for (const Marker& marker : first) EXPECT_TRUE(ids.insert({marker.ns, marker.id}).second);
}

TEST(Smoke, TfFrameForEveryEntity) {
  ros::NodeHandle nh;
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer, nh, false);  // spun by spinUntil
  for (const std::string& frame : entityFrames()) {
    EXPECT_TRUE(stc_test::spinUntil([&] { return buffer.canTransform("world", frame, ros::Time(0)); },
                                    stc_test::kLivenessSeconds))
        << "no tf world -> " << frame;
  }
}

TEST(Smoke, TickStatsAndContactsEveryTick) {
  ros::NodeHandle nh;
  TickStamps ticks(nh);
  auto& stats = ticks.stats;
  Recorder<sphere_tree_collision::ContactArray> contacts(nh, "/collision_world/contacts", 1000);
  contacts.keep_all = true;
  // Every contacts message belongs to a tick (same stamp as its tick_stats),
  // and the ticks seen are numbered in order with stamps in order.
  std::size_t matched = 0;
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        matched = 0;
        for (const auto& c : contacts.all) matched += ticks.tickAt(c.header.stamp) ? 1 : 0;
        return matched >= 10;
      },
      stc_test::kLivenessSeconds));
  for (std::size_t i = 1; i < stats.all.size(); ++i) {
    EXPECT_GT(stats.all[i].tick, stats.all[i - 1].tick);
    EXPECT_GT(stats.all[i].header.stamp, stats.all[i - 1].header.stamp);
  }
  // Pairs whose contacts are carried over (~reuse_tolerance, on by default)
  // are among the colliding ones.
  for (const auto& s : stats.all) EXPECT_LE(s.reused, s.colliding) << "tick " << s.tick;
  // The parts a phase's time is split into lie within it (test_tick_budget
  // checks that building contacts is timed).
  for (const auto& s : stats.all) {
    EXPECT_GE(s.sweep_ms, 0.0);
    EXPECT_LE(s.sweep_ms, s.integrate_ms) << "tick " << s.tick;
    EXPECT_GE(s.contacts_ms, 0.0);
    EXPECT_LE(s.contacts_ms, s.response_ms) << "tick " << s.tick;
  }
  // The default ~tick_budget (0): each step got the reported period less the node's
  // publishing as measured before it (tick_budget_rule.hpp; test_tick_budget_rule
  // checks the rule itself), a finite budget > 0, and the publishing was measured.
  double tick_rate = 0.0;
  ASSERT_TRUE(ros::param::get("~tick_rate", tick_rate));
  bool publishing_measured = false;
  for (const auto& s : stats.all) {
    EXPECT_NEAR(s.period_ms, 1e3 / tick_rate, 1e-9) << "tick " << s.tick;
    EXPECT_GE(s.publish_ms, 0.0) << "tick " << s.tick;
    const double expected_ms = stc_ros::tickBudgetSeconds(0.0, s.period_ms * 1e-3, s.publish_ms * 1e-3) * 1e3;
    EXPECT_NEAR(s.tick_budget_ms, expected_ms, 1e-9) << "tick " << s.tick;
    EXPECT_GT(s.tick_budget_ms, 0.0) << "tick " << s.tick;
    EXPECT_LE(s.tick_budget_ms, 1e3 / tick_rate + 1e-9) << "tick " << s.tick;
    publishing_measured = publishing_measured || s.publish_ms > 0.0;
  }
  EXPECT_TRUE(publishing_measured);
  // The gaze of the marker test has expired: no projection work from then on.
  ASSERT_TRUE(stc_test::spinUntil([&] { return !stats.last.gaze_active; }, stc_test::kLivenessSeconds));
  const std::uint64_t expired_at = stats.last.tick;
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.tick > expired_at; }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats.last.entities, entityFrames().size());
  EXPECT_EQ(stats.last.rejected_inputs, 0u) << stats.last.last_rejection;
  EXPECT_GT(stats.last.tick, 0u);
  EXPECT_EQ(stats.last.scheduler, "priority_queues");
  EXPECT_FALSE(stats.last.perception_used) << "no gaze published: no projection work";
}

// Static entities never move: their frames go out on /tf_static (latched, one
// message with every static frame, the camera's too), again whole when a
// static entity comes or goes; /tf carries the moving ones each tick. Last:
// it spawns an entity (and despawns it), which the tests above do not expect.
TEST(Smoke, StaticFramesOnTfStaticMovingOnesOnTf) {
  ros::NodeHandle nh;
  Recorder<tf2_msgs::TFMessage> tf(nh, "/tf", 100);
  tf.keep_all = true;
  Recorder<tf2_msgs::TFMessage> tf_static(nh, "/tf_static", 10);
  ros::Publisher spawn = nh.advertise<sphere_tree_collision::SpawnEntity>("/collision_world/spawn", 10);
  ros::Publisher despawn = nh.advertise<sphere_tree_collision::Despawn>("/collision_world/despawn", 10);
  const auto framesOf = [](const tf2_msgs::TFMessage& m) {
    std::set<std::string> out;
    for (const auto& t : m.transforms) out.insert(t.child_frame_id);
    return out;
  };
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return tf_static.count() > 0 && spawn.getNumSubscribers() > 0 && despawn.getNumSubscribers() > 0; },
      stc_test::kLivenessSeconds));
  EXPECT_EQ(framesOf(tf_static.last), std::set<std::string>{"perception_camera"}) << "no entity of the scene is static";

  sphere_tree_collision::SpawnEntity shelf;
  shelf.name = "shelf";
  shelf.preset = "cube";
  shelf.resolution = 4;
  shelf.voxel_size = 0.1;
  shelf.is_static = true;
  shelf.pose.position.z = -3.0;  // away from the scene: no contact
  shelf.pose.orientation.w = 1.0;
  spawn.publish(shelf);
  ASSERT_TRUE(stc_test::spinUntil([&] { return framesOf(tf_static.last).count("shelf") == 1; },
                                  stc_test::kLivenessSeconds))
      << "the static entity's frame on /tf_static";
  EXPECT_EQ(framesOf(tf_static.last).count("perception_camera"), 1u) << "sent whole: the camera's frame stays";
  for (const auto& t : tf_static.last.transforms) {
    if (t.child_frame_id == "shelf") EXPECT_EQ(t.transform.translation.z, -3.0);
  }

  tf.clear();
  ASSERT_TRUE(tf.waitFor(3, stc_test::kLivenessSeconds));
  for (const auto& m : tf.all) {
    const std::set<std::string> frames = framesOf(m);
    EXPECT_EQ(frames.count("shelf"), 0u) << "a static frame on /tf";
    for (const std::string& e : entityFrames()) EXPECT_EQ(frames.count(e), 1u) << "moving " << e << " not on /tf";
  }

  sphere_tree_collision::Despawn gone;
  gone.name = "shelf";
  despawn.publish(gone);
  ASSERT_TRUE(stc_test::spinUntil([&] { return framesOf(tf_static.last).count("shelf") == 0; },
                                  stc_test::kLivenessSeconds))
      << "the despawned static entity's frame still on /tf_static";
  EXPECT_EQ(framesOf(tf_static.last), std::set<std::string>{"perception_camera"});
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "smoke_test"); }
