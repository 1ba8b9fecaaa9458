// Bad input: each malformed message is rejected with its field named, counted
// in tick_stats (per topic) and logged on /rosout, and changes nothing else.
#include "rostest_util.hpp"

#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <rosgraph_msgs/Log.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <cmath>
#include <functional>
#include <limits>

namespace {

using sphere_tree_collision::SpawnEntity;
using sphere_tree_collision::TickStats;
using stc_test::Recorder;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

SpawnEntity goodSpawn() {
  SpawnEntity m;
  m.preset = "cube";
  m.resolution = 4;
  m.voxel_size = 0.05;
  m.pose.position.z = 2.0;
  m.pose.orientation.w = 1.0;
  m.density = 1000.0;
  m.restitution = 0.3;
  m.friction = 0.5;
  return m;
}

SpawnEntity grid(std::uint32_t n, std::size_t bytes, std::uint8_t value) {
  SpawnEntity m = goodSpawn();
  m.preset.clear();
  m.dims = {n, n, n};
  m.occupancy.assign(bytes, value);
  return m;
}

SpawnEntity spawnWith(const std::function<void(SpawnEntity&)>& edit) {
  SpawnEntity m = goodSpawn();
  edit(m);
  return m;
}

struct Case {
  std::string topic;      // as counted in tick_stats and named in last_rejection
  std::string field;      // the field the rejection must name
  std::function<void()> publish;
};

class BadInput : public testing::Test {
 protected:
  BadInput()
      : spawn_(nh_.advertise<SpawnEntity>("/collision_world/spawn", 100)),
        despawn_(nh_.advertise<sphere_tree_collision::Despawn>("/collision_world/despawn", 100)),
        gaze_(nh_.advertise<sphere_tree_collision::GazePoint>("/collision_world/gaze", 100)),
        clicked_(nh_.advertise<geometry_msgs::PointStamped>("/clicked_point", 100)),
        stats_(nh_, "/collision_world/tick_stats"),
        rosout_(nh_, "/rosout", 1000),
        listener_(tf_, nh_, false) {
    rosout_.keep_all = true;
    EXPECT_TRUE(stc_test::spinUntil(
        [&] {
          return spawn_.getNumSubscribers() > 0 && despawn_.getNumSubscribers() > 0 &&
                 gaze_.getNumSubscribers() > 0 && clicked_.getNumSubscribers() > 0 && stats_.count() > 0;
        }, stc_test::kLivenessSeconds));
  }

  static std::uint64_t counter(const TickStats& s, const std::string& topic) {
    if (topic == "spawn") return s.rejected_spawn;
    if (topic == "despawn") return s.rejected_despawn;
    if (topic == "gaze") return s.rejected_gaze;
    return s.rejected_clicked_point;
  }

  sphere_tree_collision::GazePoint gaze(double x, double y, double age_s) const {
    sphere_tree_collision::GazePoint g;
    g.header.stamp = ros::Time::now() - ros::Duration(age_s);
    g.x = x;
    g.y = y;
    return g;
  }

  geometry_msgs::PointStamped clicked(double x, double y, double z, const std::string& frame = "world") const {
    geometry_msgs::PointStamped p;
    p.header.frame_id = frame;
    p.header.stamp = ros::Time::now();
    p.point.x = x;
    p.point.y = y;
    p.point.z = z;
    return p;
  }

  ros::NodeHandle nh_;
  ros::Publisher spawn_, despawn_, gaze_, clicked_;
  Recorder<TickStats> stats_;
  Recorder<rosgraph_msgs::Log> rosout_;
  tf2_ros::Buffer tf_;
  tf2_ros::TransformListener listener_;
};

TEST_F(BadInput, EveryMalformedKindIsRejectedByFieldAndNothingChanges) {
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf_.canTransform("world", "cube", ros::Time(0)); }, stc_test::kLivenessSeconds));
  const auto cube_before = tf_.lookupTransform("world", "cube", ros::Time(0)).transform.translation;
  const std::uint32_t entities = stats_.last.entities;
  ASSERT_EQ(entities, 6u) << "the default scene";

  const auto spawn = [&](SpawnEntity m) { return [this, m] { spawn_.publish(m); }; };
  const std::vector<Case> cases{
      {"spawn", "pose.position", spawn(spawnWith([](SpawnEntity& m) { m.pose.position.x = kNaN; }))},
      {"spawn", "pose.position", spawn(spawnWith([](SpawnEntity& m) { m.pose.position.y = kInf; }))},
      {"spawn", "twist.linear", spawn(spawnWith([](SpawnEntity& m) { m.twist.linear.z = -kInf; }))},
      {"spawn", "twist.angular", spawn(spawnWith([](SpawnEntity& m) { m.twist.angular.x = kNaN; }))},
      // Finite but beyond the limits (~world_extent, ~max_speed, ~max_spin, ~min_density).
      {"spawn", "pose.position", spawn(spawnWith([](SpawnEntity& m) { m.pose.position.x = 1e300; }))},
      {"spawn", "twist.linear", spawn(spawnWith([](SpawnEntity& m) { m.twist.linear.x = 1e308; }))},
      {"spawn", "twist.angular", spawn(spawnWith([](SpawnEntity& m) { m.twist.angular.y = 1e308; }))},
      {"spawn", "density", spawn(spawnWith([](SpawnEntity& m) { m.density = 5e-324; }))},
      {"spawn", "density", spawn(spawnWith([](SpawnEntity& m) { m.density = 1e-310; }))},
      {"spawn", "occupancy", spawn(grid(2, 7, 1))},   // dims x data mismatch
      {"spawn", "occupancy", spawn(grid(2, 8, 0))},   // empty grid
      {"spawn", "voxel_size", spawn([] { auto m = grid(2, 8, 1); m.voxel_size = 0.0; return m; }())},
      {"spawn", "voxel_size", spawn(spawnWith([](SpawnEntity& m) { m.voxel_size = -0.1; }))},
      {"spawn", "voxel_size", spawn(spawnWith([](SpawnEntity& m) { m.voxel_size = kNaN; }))},
      {"spawn", "dims", spawn(grid(100, 1000000, 1))},  // over ~max_voxels
      {"spawn", "dims", spawn([] { auto m = grid(2, 8, 1); m.dims[1] = 0; return m; }())},
      {"spawn", "resolution", spawn(spawnWith([](SpawnEntity& m) { m.resolution = 100000; }))},
      {"spawn", "pose.orientation", spawn(spawnWith([](SpawnEntity& m) { m.pose.orientation.w = 0.5; }))},
      // All four zero is the identity (left out); w 0 with x 0.5 is not a rotation.
      {"spawn", "pose.orientation", spawn(spawnWith([](SpawnEntity& m) { m.pose.orientation.w = 0.0; m.pose.orientation.x = 0.5; }))},
      {"spawn", "pose.orientation", spawn(spawnWith([](SpawnEntity& m) { m.pose.orientation.x = kNaN; }))},
      {"spawn", "preset", spawn(spawnWith([](SpawnEntity& m) { m.preset = "dodecahedron"; }))},
      {"spawn", "preset", spawn([] { auto m = grid(2, 8, 1); m.preset = "cube"; return m; }())},
      {"spawn", "preset", spawn(spawnWith([](SpawnEntity& m) { m.preset.clear(); }))},
      {"spawn", "density", spawn(spawnWith([](SpawnEntity& m) { m.density = kNaN; }))},  // 0 is ~default_density
      {"spawn", "density", spawn(spawnWith([](SpawnEntity& m) { m.density = -5.0; }))},
      {"spawn", "density", spawn(spawnWith([](SpawnEntity& m) { m.density = kInf; }))},
      {"spawn", "restitution", spawn(spawnWith([](SpawnEntity& m) { m.restitution = 1.5; }))},
      {"spawn", "restitution", spawn(spawnWith([](SpawnEntity& m) { m.restitution = -0.1; }))},
      {"spawn", "restitution", spawn(spawnWith([](SpawnEntity& m) { m.restitution = kNaN; }))},
      {"spawn", "friction", spawn(spawnWith([](SpawnEntity& m) { m.friction = -1.0; }))},
      {"spawn", "name", spawn(spawnWith([](SpawnEntity& m) { m.name = "cube"; }))},  // taken
      {"spawn", "name", spawn(spawnWith([](SpawnEntity& m) { m.name = "not a frame"; }))},
      {"spawn", "name", spawn(spawnWith([](SpawnEntity& m) { m.name = "entity_3"; }))},  // reserved
      {"spawn", "color", spawn(spawnWith([](SpawnEntity& m) { m.color.r = 2.0f; m.color.a = 1.0f; }))},
      // Control bytes in strings: a path would be cut at the NUL (issue 47).
      {"spawn", "mesh_resource", spawn([] {
         SpawnEntity m = goodSpawn();
         m.preset.clear();
         m.mesh_resource = std::string("package://sphere_tree_collision/meshes/bumpy_scan.stl") + '\0' + ".obj";
         return m;
       }())},
      {"spawn", "preset", spawn(spawnWith([](SpawnEntity& m) { m.preset = "cube\n"; }))},
      // A path outside ~mesh_roots (none here: only package:// is read), existing or not (issue 47).
      {"spawn", "mesh_resource", spawn(spawnWith([](SpawnEntity& m) { m.preset.clear(); m.mesh_resource = "file:///etc/passwd"; }))},
      {"spawn", "mesh_resource", spawn(spawnWith([](SpawnEntity& m) { m.preset.clear(); m.mesh_resource = "/nonexistent/a.stl"; }))},
      {"despawn", "id", [&] { sphere_tree_collision::Despawn d; d.id = 999999; despawn_.publish(d); }},
      {"despawn", "name", [&] { sphere_tree_collision::Despawn d; d.name = "nobody"; despawn_.publish(d); }},
      {"gaze", "header.stamp", [&] { gaze_.publish(gaze(100, 100, 5.0)); }},   // stale
      {"gaze", "header.stamp", [&] { gaze_.publish(gaze(100, 100, -5.0)); }},  // from the future
      {"gaze", "header.stamp", [&] {  // at the end of the time range: no ROS time arithmetic throws
         auto g = gaze(100, 100, 0.0);
         g.header.stamp.sec = 4294967295u;
         gaze_.publish(g);
       }},
      {"gaze", "x", [&] { gaze_.publish(gaze(5000, 100, 0.0)); }},             // off screen
      {"gaze", "y", [&] { gaze_.publish(gaze(100, -1, 0.0)); }},
      {"gaze", "x", [&] { gaze_.publish(gaze(kNaN, 100, 0.0)); }},
      {"clicked_point", "point", [&] { clicked_.publish(clicked(0.0, -10.0, 1.0)); }},  // behind the camera
      {"clicked_point", "point", [&] { clicked_.publish(clicked(50.0, 0.0, 0.5)); }},   // in front, off screen
      {"clicked_point", "point", [&] { clicked_.publish(clicked(kNaN, 0.0, 0.5)); }},
      {"clicked_point", "point", [&] { clicked_.publish(clicked(0.0, 1e300, 0.5)); }},  // past ~world_extent
      {"clicked_point", "header.frame_id", [&] { clicked_.publish(clicked(0.0, 0.0, 0.5, "map")); }},
  };

  std::uint64_t total_before = stats_.last.rejected_inputs;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.topic + " / " + c.field);
    const std::uint64_t before = counter(stats_.last, c.topic);
    rosout_.clear();
    c.publish();
    ASSERT_TRUE(stc_test::spinUntil([&] { return counter(stats_.last, c.topic) == before + 1; }, stc_test::kLivenessSeconds))
        << "not counted; last rejection '" << stats_.last.last_rejection << "'";
    EXPECT_EQ(stats_.last.last_rejection.rfind(c.topic + ": " + c.field + ": ", 0), 0u)
        << "last rejection '" << stats_.last.last_rejection << "'";
    EXPECT_EQ(stats_.last.rejected_inputs, total_before + 1);
    total_before = stats_.last.rejected_inputs;
    // The same rejection as an ERROR on /rosout, naming the field.
    const std::string expected = "rejected " + c.topic + " message: " + c.field + ": ";
    EXPECT_TRUE(stc_test::spinUntil(
        [&] {
          for (const auto& log : rosout_.all) {
            if (log.level == rosgraph_msgs::Log::ERROR && log.msg.find(expected) != std::string::npos) return true;
          }
          return false;
        }, stc_test::kLivenessSeconds))
        << "no /rosout error containing '" << expected << "'";
    EXPECT_EQ(stats_.last.entities, entities);
  }

  // Nothing else changed: same entities, the world kept ticking, the cube
  // (spinning in place without gravity) is where it was.
  const std::uint64_t tick = stats_.last.tick;
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.tick > tick + 5; }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats_.last.entities, entities);
  EXPECT_FALSE(stats_.last.gaze_active);
  const auto cube_after = tf_.lookupTransform("world", "cube", ros::Time(0)).transform.translation;
  EXPECT_NEAR(cube_after.x, cube_before.x, 1e-9);
  EXPECT_NEAR(cube_after.y, cube_before.y, 1e-9);
  EXPECT_NEAR(cube_after.z, cube_before.z, 1e-9);

  // Good input still works afterwards.
  spawn_.publish(spawnWith([](SpawnEntity& m) { m.name = "late"; }));
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.entities == entities + 1; }, stc_test::kLivenessSeconds));
  // The shortest spawn: density, resolution, voxel_size and orientation left at 0 take their defaults.
  SpawnEntity shortest;
  shortest.name = "shortest";
  shortest.preset = "rock";
  shortest.pose.position.z = 2.0;
  spawn_.publish(shortest);
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.entities == entities + 2; }, stc_test::kLivenessSeconds))
      << "last rejection '" << stats_.last.last_rejection << "'";
  sphere_tree_collision::GazePoint good;  // stamp 0: "now" to the node, never stale however late it arrives
  good.x = 640;
  good.y = 360;
  gaze_.publish(good);
  EXPECT_TRUE(stc_test::spinUntil([&] { return stats_.last.gaze_active; }, stc_test::kLivenessSeconds));
  clicked_.publish(clicked(0.0, 0.0, 0.5));
  EXPECT_TRUE(stc_test::spinUntil([&] { return stats_.last.gaze_active; }, stc_test::kLivenessSeconds));
  const std::uint64_t tick_now = stats_.last.tick;
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.tick >= tick_now + 10; }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats_.last.rejected_inputs, total_before) << "good input is not counted as rejected";
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "bad_input_test"); }
