// Fracture through the ROS interface: a rock spawned through ~spawn with a
// strength breaks on a static slab. Its pieces replace it in ~entities, get
// tf frames, and in the first ~entity_states that holds them (the break tick:
// states are published every tick) they move as the parent did: one angular
// velocity, and linear velocities v_i - v_j = w x (x_i - x_j), the rigid
// motion whose momentum the core test checks to 1e-9 (test_fracture).
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/EntityList.h>
#include <sphere_tree_collision/EntityStates.h>
#include <sphere_tree_collision/Spawn.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace {

using sphere_tree_collision::EntityStates;

const std::string kNode = "/collision_world/";

Eigen::Vector3d vec(const geometry_msgs::Vector3& v) { return {v.x, v.y, v.z}; }
Eigen::Vector3d vec(const geometry_msgs::Point& v) { return {v.x, v.y, v.z}; }

bool hasPieces(const EntityStates& m) {
  for (const auto& name : m.names) {
    if (name.rfind("rock/piece", 0) == 0) return true;
  }
  return false;
}

TEST(Fracture, RockBreaksOnTheSlabIntoPiecesMovingAsItDid) {
  ros::NodeHandle nh;
  stc_test::Recorder<EntityStates> states(nh, kNode + "entity_states", 1000);
  states.keep_all = true;
  stc_test::Recorder<sphere_tree_collision::EntityList> list(nh, kNode + "entities");
  tf2_ros::Buffer tf;
  tf2_ros::TransformListener listener(tf, nh, false);
  ASSERT_TRUE(ros::service::waitForService(kNode + "spawn", ros::Duration(stc_test::kLivenessSeconds)));
  ASSERT_TRUE(states.waitFor(1, stc_test::kLivenessSeconds));

  sphere_tree_collision::Spawn bad;
  bad.request.entity.name = "bad";
  bad.request.entity.preset = "rock";
  bad.request.entity.voxel_size = 0.05;
  bad.request.entity.pose.orientation.w = 1.0;
  bad.request.entity.density = 1000.0;
  bad.request.entity.strength = -1.0;
  ASSERT_TRUE(ros::service::call(kNode + "spawn", bad));
  EXPECT_FALSE(bad.response.success);
  EXPECT_NE(bad.response.message.find("strength"), std::string::npos) << bad.response.message;

  sphere_tree_collision::Spawn rock = bad;
  rock.request.entity.name = "rock";
  rock.request.entity.resolution = 8;
  rock.request.entity.seed = 3;
  rock.request.entity.pose.position.z = 0.0;  // slab top at -0.9
  rock.request.entity.twist.linear.x = 0.5;
  rock.request.entity.twist.linear.z = -6.0;
  rock.request.entity.twist.angular.y = 2.0;
  rock.request.entity.restitution = 0.3;
  rock.request.entity.friction = 0.6;
  rock.request.entity.strength = 1.0;
  ASSERT_TRUE(ros::service::call(kNode + "spawn", rock));
  ASSERT_TRUE(rock.response.success) << rock.response.message;

  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        for (const auto& m : states.all) {
          if (hasPieces(m)) return true;
        }
        return false;
      },
      stc_test::kLivenessSeconds))
      << "the rock never broke";
  const EntityStates* birth = nullptr;
  for (const auto& m : states.all) {
    if (hasPieces(m)) {
      birth = &m;
      break;
    }
  }
  std::vector<std::size_t> pieces;
  for (std::size_t i = 0; i < birth->names.size(); ++i) {
    EXPECT_NE(birth->names[i], "rock") << "the parent is still there";
    if (birth->names[i].rfind("rock/piece", 0) == 0) pieces.push_back(i);
  }
  ASSERT_GE(pieces.size(), 2u);
  const std::size_t a = pieces[0];
  const Eigen::Vector3d w = vec(birth->twists[a].angular);
  for (const std::size_t b : pieces) {
    EXPECT_LE((vec(birth->twists[b].angular) - w).norm(), 1e-9 * w.norm()) << birth->names[b];
    const Eigen::Vector3d dv = vec(birth->twists[b].linear) - vec(birth->twists[a].linear);
    const Eigen::Vector3d dx = vec(birth->poses[b].position) - vec(birth->poses[a].position);
    EXPECT_LE((dv - w.cross(dx)).norm(), 1e-9 * (1.0 + dv.norm())) << birth->names[b];
  }

  // ~entities and tf follow the pieces.
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        int n = 0;
        for (const auto& e : list.last.entities) n += e.name.rfind("rock/piece", 0) == 0 ? 1 : 0;
        return n >= 2;
      },
      stc_test::kLivenessSeconds));
  for (const auto& e : list.last.entities) EXPECT_NE(e.name, "rock");
  EXPECT_TRUE(stc_test::spinUntil([&] { return tf.canTransform("world", birth->names[a], ros::Time(0)); },
                                  stc_test::kLivenessSeconds))
      << "no tf frame " << birth->names[a];
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "fracture_test"); }
