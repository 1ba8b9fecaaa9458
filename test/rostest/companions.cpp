// Companion nodes: gaze_simulator's four modes put the gaze where they say,
// and rockfall_spawner drops valid rocks at its rate, keeping at most
// max_rocks alive (oldest despawned first).
#include "rostest_util.hpp"

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/ros/conversions.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <cmath>
#include <set>

namespace {

using sphere_tree_collision::GazePoint;
using stc_test::Recorder;

constexpr double kWidth = 1280, kHeight = 720;  // the world node's default image

bool onImage(const GazePoint& g) { return g.x >= 0 && g.y >= 0 && g.x <= kWidth && g.y <= kHeight; }

TEST(Companions, FixedGazeStaysOnItsPixel) {
  ros::NodeHandle nh;
  Recorder<GazePoint> gaze(nh, "/fixed/gaze");
  gaze.keep_all = true;
  ASSERT_TRUE(gaze.waitFor(10, 10.0));
  for (const auto& g : gaze.all) {
    EXPECT_DOUBLE_EQ(g.x, 100.0);
    EXPECT_DOUBLE_EQ(g.y, 200.0);
  }
  EXPECT_NEAR(gaze.rate(), 30.0, 12.0) << "default ~rate 30 Hz";
}

TEST(Companions, CircleGazeGoesRoundTheCentre) {
  ros::NodeHandle nh;
  Recorder<GazePoint> gaze(nh, "/circle/gaze");
  gaze.keep_all = true;
  ASSERT_TRUE(gaze.waitFor(40, 10.0));  // > one 2 s period at 30 Hz
  double min_angle = 10, max_angle = -10;
  for (const auto& g : gaze.all) {
    EXPECT_NEAR(std::hypot(g.x - 0.5 * kWidth, g.y - 0.5 * kHeight), 150.0, 1e-6);
    const double a = std::atan2(g.y - 0.5 * kHeight, g.x - 0.5 * kWidth);
    min_angle = std::min(min_angle, a);
    max_angle = std::max(max_angle, a);
  }
  EXPECT_GT(max_angle - min_angle, 5.0) << "most of a turn within a period";
}

TEST(Companions, SaccadesJumpBetweenPixelsOnTheImage) {
  ros::NodeHandle nh;
  Recorder<GazePoint> gaze(nh, "/saccades/gaze");
  gaze.keep_all = true;
  ASSERT_TRUE(gaze.waitFor(45, 10.0));  // 1.5 s at 30 Hz: ~7 saccades of 0.2 s
  std::set<std::pair<double, double>> targets;
  for (const auto& g : gaze.all) {
    EXPECT_TRUE(onImage(g)) << g.x << ", " << g.y;
    targets.insert({g.x, g.y});
  }
  EXPECT_GE(targets.size(), 4u) << "the gaze jumps";
  EXPECT_LE(targets.size(), 12u) << "and rests between jumps";
}

TEST(Companions, FollowGazeTracksTheEntitysProjection) {
  ros::NodeHandle nh;
  tf2_ros::Buffer tf;
  tf2_ros::TransformListener listener(tf, nh, false);
  ros::Publisher spawn = nh.advertise<sphere_tree_collision::SpawnEntity>("/spawn", 10);
  ASSERT_TRUE(stc_test::spinUntil([&] { return spawn.getNumSubscribers() > 0; }, 10.0));
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
  ASSERT_TRUE(gaze.waitFor(1, 10.0));
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return tf.canTransform("world", "probe", ros::Time(0)) && tf.canTransform("world", "perception_camera", ros::Time(0)); },
      10.0));
  stc_test::spinFor(0.5);
  const auto cam = tf.lookupTransform("world", "perception_camera", ros::Time(0));
  stc::Camera camera;
  camera.camera_to_world.position = stc_ros::toEigen(cam.transform.translation);
  camera.camera_to_world.orientation = stc_ros::toEigen(cam.transform.rotation).normalized();
  stc::Perception perception;
  perception.setCamera(camera);
  int checked = 0;
  for (int i = 0; i < 10; ++i) {
    gaze.clear();
    ASSERT_TRUE(gaze.waitFor(1, 2.0));
    const auto at = tf.lookupTransform("world", "probe", ros::Time(0));
    const auto pixel = perception.project(stc_ros::toEigen(at.transform.translation));
    ASSERT_TRUE(pixel.has_value());
    // The simulator projects the latest tf it has; the probe moves 0.2 m/s, a
    // few px per tick, so allow a tick or two of lag.
    EXPECT_NEAR(gaze.last.x, pixel->x(), 25.0);
    EXPECT_NEAR(gaze.last.y, pixel->y(), 25.0);
    ++checked;
  }
  EXPECT_EQ(checked, 10);
}

TEST(Companions, RockfallDropsValidRocksAndKeepsAtMostMaxRocks) {
  ros::NodeHandle nh;
  Recorder<sphere_tree_collision::SpawnEntity> spawns(nh, "/spawn");
  Recorder<sphere_tree_collision::Despawn> despawns(nh, "/despawn");
  Recorder<sphere_tree_collision::TickStats> stats(nh, "/tick_stats");
  spawns.keep_all = true;
  despawns.keep_all = true;
  ASSERT_TRUE(spawns.waitFor(8, 10.0));
  EXPECT_NEAR(spawns.rate(), 5.0, 2.0);
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
  ASSERT_TRUE(stats.waitFor(1, 5.0));
  EXPECT_EQ(stats.last.rejected_spawn, 0u) << stats.last.last_rejection;
  EXPECT_LE(stats.last.entities, 4u);
  EXPECT_GE(stats.last.entities, 3u);
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "companions_test"); }
