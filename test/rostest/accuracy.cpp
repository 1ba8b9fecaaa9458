// Accuracy against FCL, end to end through ROS. For each received tick the
// test rebuilds the scene from tf (entity poses stamped with the tick) and FCL
// meshes of the same voxel shapes (same body origin: the centre of mass), and
// checks the node's contacts:
//   unlimited budget: no pair FCL finds colliding is missing;
//   tight budget: the same (policy accept), and every accepted unresolved
//   pair's gap bound is >= FCL's true distance.
// It prints the false-positive rate and the mean true gap of false positives.
#include "rostest_util.hpp"

#include "fcl_mesh.hpp"
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <map>
#include <random>

namespace {

using sphere_tree_collision::ContactArray;
using sphere_tree_collision::SpawnEntity;

const char* const kPresets[] = {"rock", "cube", "L", "ring", "rod"};

struct Body {
  std::string frame;
  std::shared_ptr<stc::truth::FclMesh> mesh;
  double radius = 0.0;  // bounding ball about the centre of mass: a cheap pre-filter
};

struct PairReport {
  bool resolved = true;
  double gap_bound = 0.0;
};

struct Tally {
  int ticks = 0, skipped = 0;
  long fcl_colliding = 0, missed = 0, reported = 0, false_positives = 0, unresolved = 0, bound_violations = 0;
  double false_positive_gap = 0.0;
};

class Accuracy : public testing::Test {
 protected:
  // Spawns the same seeded cluster into world `ns` (entities named <prefix><k>;
  // ids are assigned in spawn order by a fresh world, checked below).
  std::vector<Body> spawnCluster(const std::string& ns, const std::string& prefix, int count) {
    ros::Publisher spawn = nh_.advertise<SpawnEntity>("/" + ns + "/spawn", 100);
    stc_test::Recorder<sphere_tree_collision::TickStats> stats(nh_, "/" + ns + "/tick_stats");
    EXPECT_TRUE(stc_test::spinUntil([&] { return spawn.getNumSubscribers() > 0 && stats.count() > 0; }, 15.0));
    std::mt19937 random(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Body> bodies;
    for (int k = 0; k < count; ++k) {
      SpawnEntity m;
      m.name = prefix + std::to_string(k);
      m.preset = kPresets[k % 5];
      m.resolution = 8;
      m.seed = static_cast<std::uint32_t>(k);
      m.voxel_size = 0.05;
      const stc::Vec3 p(0.45 * u(random), 0.45 * u(random), 1.0 + 0.45 * u(random));
      const stc::Quat q = stc::Quat(Eigen::AngleAxisd(M_PI * u(random), stc::Vec3(u(random), u(random), u(random)).normalized()));
      m.pose = stc_ros::toPoseMsg(stc::Pose{p, q});
      m.twist.linear = stc_ros::toVector3Msg(-0.15 * p.normalized().cwiseProduct(stc::Vec3(1, 1, 0)) + 0.05 * stc::Vec3(u(random), u(random), u(random)));
      m.twist.angular = stc_ros::toVector3Msg(stc::Vec3(u(random), u(random), u(random)));
      m.density = 1000.0;
      m.restitution = 0.3;
      m.friction = 0.5;
      spawn.publish(m);

      stc::PresetParams params;
      params.resolution = 8;
      params.voxel_size = 0.05;
      params.seed = m.seed;
      const stc::VoxelShape shape = stc::makePreset(m.preset, params);
      const stc::Vec3 origin = stc::computeMassProperties(shape, 1.0).centre_of_mass;
      Body b;
      b.frame = m.name;
      b.mesh = stc::truth::makeFclMesh(shape, origin);
      const stc::truth::SurfaceMesh surface = stc::truth::buildSurfaceMesh(shape, origin);
      for (const stc::Vec3& v : surface.vertices) b.radius = std::max(b.radius, v.norm());
      bodies.push_back(b);
    }
    EXPECT_TRUE(stc_test::spinUntil([&] { return stats.last.entities == static_cast<std::uint32_t>(count); }, 10.0))
        << ns << ": last rejection '" << stats.last.last_rejection << "'";
    return bodies;
  }

  Tally check(const std::string& ns, const std::string& world_frame, const std::vector<Body>& bodies, int ticks) {
    tf2_ros::Buffer tf(ros::Duration(30.0));
    tf2_ros::TransformListener listener(tf, nh_, false);
    std::deque<ContactArray> pending;
    auto sub = nh_.subscribe<ContactArray>("/" + ns + "/contacts", 100,
                                           [&](const ContactArray::ConstPtr& m) { pending.push_back(*m); });
    Tally tally;
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(40.0);
    while (tally.ticks < ticks && ros::WallTime::now() < deadline) {
      stc_test::spinFor(0.05);
      // Let the tf of a tick arrive before checking it.
      while (!pending.empty() && (ros::Time::now() - pending.front().header.stamp).toSec() > 0.3) {
        const ContactArray msg = pending.front();
        pending.pop_front();
        checkTick(msg, world_frame, bodies, tf, tally);
      }
    }
    return tally;
  }

  void checkTick(const ContactArray& msg, const std::string& world_frame, const std::vector<Body>& bodies,
                 tf2_ros::Buffer& tf, Tally& tally) {
    const std::size_t n = bodies.size();
    std::vector<stc::Pose> poses(n);
    for (std::size_t k = 0; k < n; ++k) {
      try {
        const auto t = tf.lookupTransform(world_frame, bodies[k].frame, msg.header.stamp);
        poses[k].position = stc_ros::toEigen(t.transform.translation);
        poses[k].orientation = stc_ros::toEigen(t.transform.rotation).normalized();
      } catch (const tf2::TransformException&) {
        ++tally.skipped;
        return;
      }
    }
    ++tally.ticks;
    std::map<std::pair<std::uint32_t, std::uint32_t>, PairReport> reported;
    for (const auto& c : msg.contacts) {
      ASSERT_LT(c.entity_a, n);
      ASSERT_LT(c.entity_b, n);
      const auto key = std::minmax(c.entity_a, c.entity_b);
      PairReport& r = reported[key];
      r.resolved = c.resolved;
      r.gap_bound = std::max(r.gap_bound, c.gap_bound);
      // Ids follow spawn order: a contact lies within reach of both bodies.
      for (std::uint32_t id : {c.entity_a, c.entity_b}) {
        EXPECT_LT((stc_ros::toEigen(c.point) - poses[id].position).norm(), bodies[id].radius + 0.2)
            << "contact far from entity " << id << ": ids do not follow spawn order?";
      }
    }
    for (std::uint32_t i = 0; i < n; ++i) {
      for (std::uint32_t j = i + 1; j < n; ++j) {
        const auto it = reported.find({i, j});
        const bool near = (poses[i].position - poses[j].position).norm() <= bodies[i].radius + bodies[j].radius;
        const bool colliding = near && stc::truth::exactCollide(*bodies[i].mesh, poses[i], *bodies[j].mesh, poses[j]);
        tally.fcl_colliding += colliding;
        if (colliding && it == reported.end()) {
          ++tally.missed;
          ADD_FAILURE() << "tick " << msg.header.stamp << ": FCL finds " << bodies[i].frame << " and "
                        << bodies[j].frame << " colliding, the node reports no contact";
        }
        if (it == reported.end()) continue;
        ++tally.reported;
        if (!it->second.resolved) ++tally.unresolved;
        if (colliding) continue;
        const double distance = stc::truth::exactDistance(*bodies[i].mesh, poses[i], *bodies[j].mesh, poses[j]);
        ++tally.false_positives;
        tally.false_positive_gap += distance;
        if (!it->second.resolved && it->second.gap_bound + 1e-9 < distance) {
          ++tally.bound_violations;
          ADD_FAILURE() << bodies[i].frame << "-" << bodies[j].frame << ": gap bound " << it->second.gap_bound
                        << " < FCL distance " << distance;
        }
      }
    }
  }

  static void print(const std::string& name, const Tally& t) {
    std::printf("[accuracy %s] ticks %d (skipped %d), FCL colliding pair-ticks %ld, missed %ld, reported %ld "
                "(unresolved %ld), false positives %ld = %.1f %% of reported, mean true gap of false positives "
                "%.4f m, bound violations %ld\n",
                name.c_str(), t.ticks, t.skipped, t.fcl_colliding, t.missed, t.reported, t.unresolved,
                t.false_positives, t.reported ? 100.0 * t.false_positives / t.reported : 0.0,
                t.false_positives ? t.false_positive_gap / t.false_positives : 0.0, t.bound_violations);
  }

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_{"~"};
};

TEST_F(Accuracy, UnlimitedBudgetMissesNoCollision) {
  const int entities = pnh_.param("entities", 16), ticks = pnh_.param("ticks", 40);
  const auto bodies = spawnCluster("unlimited", "u", entities);
  const Tally t = check("unlimited", "world_unlimited", bodies, ticks);
  print("unlimited", t);
  EXPECT_GE(t.ticks, ticks);
  EXPECT_GT(t.fcl_colliding, 0) << "the cluster must collide for the test to mean anything";
  EXPECT_EQ(t.missed, 0);
  EXPECT_EQ(t.unresolved, 0) << "an unlimited budget resolves every pair";
}

TEST_F(Accuracy, TightBudgetBoundsEveryAcceptedGap) {
  const int entities = pnh_.param("entities", 16), ticks = pnh_.param("ticks", 40);
  const auto bodies = spawnCluster("tight", "t", entities);
  const Tally t = check("tight", "world_tight", bodies, ticks);
  print("tight", t);
  EXPECT_GE(t.ticks, ticks);
  EXPECT_GT(t.unresolved, 0) << "the budget must be tight for this test to mean anything";
  EXPECT_EQ(t.bound_violations, 0);
  EXPECT_EQ(t.missed, 0) << "policy accept: unresolved pairs are reported, so nothing is missed";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "accuracy_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
