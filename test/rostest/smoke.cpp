// Smoke test: the node publishes what it advertises, at the configured rates.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <map>
#include <set>

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

// Rates are measured over a few seconds of wall time; the bound is loose
// (the machine may be busy) but far from "not publishing" or "every tick".
constexpr double kRateTolerance = 0.35;
constexpr double kWindow = 3.0;

TEST(Smoke, AdvertisedTypes) {
  ros::NodeHandle nh;
  ASSERT_TRUE(stc_test::spinUntil([] { return stc_test::topicType("/tick_stats") != ""; }, 10.0));
  EXPECT_EQ(stc_test::topicType("/markers"), "visualization_msgs/MarkerArray");
  EXPECT_EQ(stc_test::topicType("/tick_stats"), "sphere_tree_collision/TickStats");
  EXPECT_EQ(stc_test::topicType("/contacts"), "sphere_tree_collision/ContactArray");
  EXPECT_EQ(stc_test::topicType("/tf"), "tf2_msgs/TFMessage");
}

TEST(Smoke, MarkersAtConfiguredRate) {
  ros::NodeHandle nh;
  const double expected = param("marker_rate");
  stc_test::MarkerState state(nh, "/markers");
  Recorder<visualization_msgs::MarkerArray> markers(nh, "/markers", 10);
  ASSERT_TRUE(markers.waitFor(1, 10.0)) << "no marker array within 10 s";
  markers.clear();
  stc_test::spinFor(kWindow);
  EXPECT_NEAR(markers.rate(), expected, kRateTolerance * expected);

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
    EXPECT_FALSE(m.points.empty()) << key.first << "/" << key.second;
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
    EXPECT_TRUE(stc_test::spinUntil([&] { return buffer.canTransform("world", frame, ros::Time(0)); }, 10.0))
        << "no tf world -> " << frame;
  }
}

TEST(Smoke, TickStatsAndContactsAtTickRate) {
  ros::NodeHandle nh;
  const double expected = param("tick_rate");
  Recorder<sphere_tree_collision::TickStats> stats(nh, "/tick_stats");
  Recorder<sphere_tree_collision::ContactArray> contacts(nh, "/contacts");
  ASSERT_TRUE(stats.waitFor(1, 10.0));
  ASSERT_TRUE(contacts.waitFor(1, 10.0));
  stats.clear();
  contacts.clear();
  stc_test::spinFor(kWindow);
  EXPECT_NEAR(stats.rate(), expected, kRateTolerance * expected);
  EXPECT_NEAR(contacts.rate(), expected, kRateTolerance * expected);
  EXPECT_EQ(stats.last.entities, entityFrames().size());
  EXPECT_EQ(stats.last.rejected_inputs, 0u);
  EXPECT_GT(stats.last.tick, 0u);
  EXPECT_EQ(stats.last.scheduler, "priority_queues");
  EXPECT_FALSE(stats.last.perception_used) << "no gaze published: no projection work";
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "smoke_test"); }
