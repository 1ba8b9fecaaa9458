// Spawn and gaze: spawned entities get tf frames and markers; under a tight
// sphere-test budget the pair the viewer looks at is tested deeper than the
// pairs far from the gaze; despawn (by name and by id) and clear work.
#include "rostest_util.hpp"

#include "sphere_tree_collision/perception.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <std_msgs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <map>

namespace {

using sphere_tree_collision::SpawnEntity;
using stc_test::Recorder;

constexpr int kPairs = 7;
constexpr double kPairSpacing = 0.7;

class SpawnAndGaze : public testing::Test {
 protected:
  SpawnAndGaze()
      : spawn_(nh_.advertise<SpawnEntity>("/collision_world/spawn", 100)),
        despawn_(nh_.advertise<sphere_tree_collision::Despawn>("/collision_world/despawn", 10)),
        clear_(nh_.advertise<std_msgs::Empty>("/collision_world/clear", 10)),
        gaze_(nh_.advertise<sphere_tree_collision::GazePoint>("/collision_world/gaze", 10)),
        stats_(nh_, "/collision_world/tick_stats"),
        contacts_(nh_, "/collision_world/contacts"),
        markers_(nh_, "/collision_world/markers"),
        listener_(tf_, nh_, false) {
    EXPECT_TRUE(stc_test::spinUntil(
        [&] {
          return spawn_.getNumSubscribers() > 0 && despawn_.getNumSubscribers() > 0 &&
                 clear_.getNumSubscribers() > 0 && gaze_.getNumSubscribers() > 0 && stats_.count() > 0;
        },
        stc_test::kLivenessSeconds));
    // Start empty. Topics are not ordered against each other, so a clear is
    // sent only when there is something to clear, and awaited.
    if (stats_.last.entities > 0) {
      clear_.publish(std_msgs::Empty());
      EXPECT_TRUE(waitForEntities(0));
    }
  }

  testing::AssertionResult waitForEntities(std::uint32_t n) {
    if (stc_test::spinUntil([&] { return stats_.count() > 0 && stats_.last.entities == n; }, stc_test::kLivenessSeconds)) {
      return testing::AssertionSuccess();
    }
    return testing::AssertionFailure() << "world holds " << stats_.last.entities << " entities, not " << n
                                       << "; last rejection: '" << stats_.last.last_rejection << "'";
  }

  static SpawnEntity rock(const std::string& name, double x, double z, double angle) {
    SpawnEntity m;
    m.name = name;
    m.preset = "rock";
    m.resolution = 8;
    m.seed = 1;
    m.voxel_size = 0.05;
    m.pose.position.x = x;
    m.pose.position.z = z;
    const Eigen::Quaterniond q(Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()));
    m.pose.orientation.w = q.w();
    m.pose.orientation.x = q.x();
    m.pose.orientation.y = q.y();
    m.pose.orientation.z = q.z();
    m.density = 1000.0;
    m.restitution = 0.3;
    m.friction = 0.5;
    return m;
  }

  // Deepest level reached by the contacts of each pair (by nearest pair x),
  // over the next `messages` contact arrays (ticks).
  std::map<int, int> deepestLevelPerPair(std::size_t messages) {
    std::map<int, int> deepest;
    contacts_.keep_all = true;
    contacts_.clear();
    EXPECT_TRUE(contacts_.waitFor(messages, stc_test::kLivenessSeconds));
    for (const auto& array : contacts_.all) {
      for (const auto& c : array.contacts) {
        const int pair = static_cast<int>(std::lround((c.point.x + 0.5 * (kPairs - 1) * kPairSpacing) / kPairSpacing));
        if (pair < 0 || pair >= kPairs) continue;
        deepest[pair] = std::max(deepest.count(pair) ? deepest[pair] : -1, static_cast<int>(c.level));
      }
    }
    contacts_.keep_all = false;
    return deepest;
  }

  // Waits until the node has ticked n more times (judged by tick numbers).
  bool ticksLater(std::uint64_t n) {
    const std::uint64_t tick = stats_.last.tick;
    return stc_test::spinUntil([&] { return stats_.last.tick >= tick + n; }, stc_test::kLivenessSeconds);
  }

  ros::NodeHandle nh_;
  ros::Publisher spawn_, despawn_, clear_, gaze_;
  Recorder<sphere_tree_collision::TickStats> stats_;
  Recorder<sphere_tree_collision::ContactArray> contacts_;
  stc_test::MarkerState markers_;
  tf2_ros::Buffer tf_;
  tf2_ros::TransformListener listener_;
};

TEST_F(SpawnAndGaze, SpawnedEntityGetsTfFrameAndMarkers) {
  SpawnEntity probe = rock("probe", 0.4, 0.9, 0.0);
  probe.preset = "L";
  spawn_.publish(probe);
  ASSERT_TRUE(waitForEntities(1));
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf_.canTransform("world", "probe", ros::Time(0)); }, stc_test::kLivenessSeconds));
  const auto t = tf_.lookupTransform("world", "probe", ros::Time(0));
  EXPECT_NEAR(t.transform.translation.x, 0.4, 1e-9);
  EXPECT_NEAR(t.transform.translation.z, 0.9, 1e-9);

  // The markers draw it: one voxel list, frame-locked in its frame.
  ASSERT_TRUE(stc_test::spinUntil([&] { return markers_.count("voxels") == 1; }, stc_test::kLivenessSeconds));
  for (const auto& [key, m] : markers_.markers) {
    if (key.first != "voxels") continue;
    EXPECT_EQ(m.header.frame_id, "probe");
    EXPECT_TRUE(m.frame_locked);
    EXPECT_GT(m.points.size(), 10u);
  }

  // An unnamed entity gets the frame entity_<id>.
  spawn_.publish(rock("", -0.4, 0.9, 0.0));
  ASSERT_TRUE(waitForEntities(2));
  EXPECT_TRUE(stc_test::spinUntil(
      [&] {
        std::vector<std::string> frames;
        tf_._getFrameStrings(frames);
        for (const auto& f : frames) {
          if (f.rfind("entity_", 0) == 0) return true;
        }
        return false;
      }, stc_test::kLivenessSeconds));
}

TEST_F(SpawnAndGaze, ContactsNearTheGazeReachDeeperLevels) {
  // A row of overlapping rock pairs across the image.
  for (int i = 0; i < kPairs; ++i) {
    const double x = (i - 0.5 * (kPairs - 1)) * kPairSpacing;
    spawn_.publish(rock("pair" + std::to_string(i) + "_a", x, 0.5 - 0.14, 0.3 * i));
    spawn_.publish(rock("pair" + std::to_string(i) + "_b", x, 0.5 + 0.14, 0.3 * i + 1.0));
  }
  ASSERT_TRUE(waitForEntities(2 * kPairs));

  // The node's camera, to aim the gaze at a pair's pixel.
  std::vector<double> position, look_at;
  ASSERT_TRUE(ros::param::get("/collision_world/camera_position", position));
  ASSERT_TRUE(ros::param::get("/collision_world/camera_look_at", look_at));
  stc::Camera camera;
  camera.camera_to_world = stc::opticalLookAt(stc::Vec3(position[0], position[1], position[2]),
                                              stc::Vec3(look_at[0], look_at[1], look_at[2]));
  stc::Perception perception;
  perception.setCamera(camera);

  for (int target : {0, kPairs - 1}) {
    const double x = (target - 0.5 * (kPairs - 1)) * kPairSpacing;
    const auto pixel = perception.project(stc::Vec3(x, 0.0, 0.5));
    ASSERT_TRUE(pixel && perception.onScreen(*pixel));
    // Keep the gaze fresh (stamped now) while the contacts are sampled.
    ros::SteadyTimer gaze_timer = nh_.createSteadyTimer(ros::WallDuration(0.05), [&](const ros::SteadyTimerEvent&) {
      sphere_tree_collision::GazePoint g;
      g.header.stamp = ros::Time::now();
      g.x = pixel->x();
      g.y = pixel->y();
      gaze_.publish(g);
    });
    ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.gaze_active && stats_.last.perception_used; }, stc_test::kLivenessSeconds));
    ASSERT_TRUE(ticksLater(5));  // gaze messages in flight have arrived
    const std::map<int, int> deepest = deepestLevelPerPair(20);
    gaze_timer.stop();
    ASSERT_EQ(deepest.size(), static_cast<std::size_t>(kPairs)) << "every pair reports contacts";
    EXPECT_TRUE(stats_.last.interrupted) << "the budget must be tight for this test to mean anything";
    const int far = target == 0 ? kPairs - 1 : 0;
    EXPECT_GT(deepest.at(target), deepest.at(far)) << "gaze on pair " << target;
    for (const auto& [pair, level] : deepest) {
      if (pair != target) EXPECT_GE(deepest.at(target), level) << "pair " << pair << " vs gazed pair " << target;
    }
    // Until this gaze has expired, so that the next target's gaze is the one
    // the node reports active (a late message of this one is stale by then).
    ASSERT_TRUE(stc_test::spinUntil([&] { return !stats_.last.gaze_active; }, stc_test::kLivenessSeconds));
  }

  // Without gaze the scheduler says so, and no pair is favoured by position.
  ASSERT_TRUE(stc_test::spinUntil([&] { return !stats_.last.gaze_active && !stats_.last.perception_used; }, stc_test::kLivenessSeconds));
}

TEST_F(SpawnAndGaze, DespawnByNameAndIdThenClear) {
  spawn_.publish(rock("first", -0.5, 0.5, 0.0));
  spawn_.publish(rock("", 0.5, 0.5, 0.0));
  spawn_.publish(rock("third", 0.0, 1.2, 0.0));
  ASSERT_TRUE(waitForEntities(3));

  sphere_tree_collision::Despawn by_name;
  by_name.name = "first";
  despawn_.publish(by_name);
  ASSERT_TRUE(waitForEntities(2));
  EXPECT_EQ(stats_.last.rejected_despawn, 0u);

  // The unnamed entity's id, from its tf frame name (the newest entity_<id>).
  long id = -1;
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        std::vector<std::string> frames;
        tf_._getFrameStrings(frames);
        for (const auto& f : frames) {
          if (f.rfind("entity_", 0) == 0) id = std::max(id, std::stol(f.substr(7)));
        }
        return id >= 0;
      }, stc_test::kLivenessSeconds));
  sphere_tree_collision::Despawn by_id;
  by_id.id = static_cast<std::uint32_t>(id);
  despawn_.publish(by_id);
  ASSERT_TRUE(waitForEntities(1));
  EXPECT_EQ(stats_.last.rejected_despawn, 0u);

  // The name is free again once its entity is gone.
  spawn_.publish(rock("first", -0.5, 0.5, 0.0));
  ASSERT_TRUE(waitForEntities(2));
  EXPECT_EQ(stats_.last.rejected_spawn, 0u);

  ASSERT_TRUE(stc_test::spinUntil([&] { return markers_.count("voxels") == 2; }, stc_test::kLivenessSeconds))
      << "despawned entities' markers are deleted, the others stay";
  EXPECT_GT(markers_.count("tree_level_1"), 0);

  clear_.publish(std_msgs::Empty());
  ASSERT_TRUE(waitForEntities(0));
  EXPECT_TRUE(stc_test::spinUntil(
      [&] { return markers_.count("voxels") == 0 && markers_.count("tree_level_1") == 0; }, stc_test::kLivenessSeconds))
      << "cleared entities leave no markers";
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "spawn_and_gaze_test"); }
