// Fracture through the ROS interface. A rock spawned through ~spawn with a
// strength breaks on a static slab: its pieces replace it in ~entities, get
// tf frames, and in the first ~entity_states that holds them (the break tick:
// states are published every tick) they move as the parent did. Then, in
// free space, a breakable rock hits a heavier free one: every impulse is
// between the two, so the momentum (mass from ~entities x twist from
// ~entity_states) of the states just before and at the break agree, the
// pieces weigh what the rock did, and at birth no voxel of a piece (the
// voxels markers, placed by the birth poses) overlaps a voxel of another.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/EntityList.h>
#include <sphere_tree_collision/EntityStates.h>
#include <sphere_tree_collision/Spawn.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
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
  // A copy: states.all grows (and moves) while later waits spin.
  EntityStates birth_msg;
  for (const auto& m : states.all) {
    if (hasPieces(m)) {
      birth_msg = m;
      break;
    }
  }
  const EntityStates* birth = &birth_msg;
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

sphere_tree_collision::Spawn rockSpawn(const std::string& name, int seed, double y, double density,
                                       double strength) {
  sphere_tree_collision::Spawn s;
  s.request.entity.name = name;
  s.request.entity.preset = "rock";
  s.request.entity.resolution = 8;
  s.request.entity.voxel_size = 0.05;
  s.request.entity.seed = seed;
  s.request.entity.pose.position.y = y;
  s.request.entity.pose.orientation.w = 1.0;
  s.request.entity.density = density;
  s.request.entity.restitution = 0.3;
  s.request.entity.friction = 0.6;
  s.request.entity.strength = strength;
  return s;
}

// Linear momentum of the bodies `of` names in a states message, and the sum
// of the momenta's sizes (the scale of its rounding).
struct Momentum {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double scale = 0.0;
};
Momentum momentumOf(const EntityStates& m, const std::map<std::uint32_t, double>& mass,
                    const std::function<bool(const std::string&)>& of) {
  Momentum out;
  for (std::size_t i = 0; i < m.names.size(); ++i) {
    if (!of(m.names[i])) continue;
    const auto found = mass.find(m.ids[i]);
    EXPECT_NE(found, mass.end()) << "no mass in ~entities for " << m.names[i];
    if (found == mass.end()) continue;
    out.p += found->second * vec(m.twists[i].linear);
    out.scale += found->second * vec(m.twists[i].linear).norm();
  }
  return out;
}

TEST(Fracture, MomentumIsKeptThroughABreakAndPiecesDoNotOverlapAtBirth) {
  ros::NodeHandle nh;
  stc_test::Recorder<EntityStates> states(nh, kNode + "entity_states", 1000);
  states.keep_all = true;
  stc_test::Recorder<sphere_tree_collision::EntityList> lists(nh, kNode + "entities", 100);
  lists.keep_all = true;
  stc_test::Recorder<sphere_tree_collision::TickStats> stats(nh, kNode + "tick_stats", 1000);
  stats.keep_all = true;
  // Every voxels marker ever added, by entity id: a piece that breaks again
  // soon after birth is deleted, but its marker (sent in its birth tick:
  // ~marker_rate is ~rate) stays here.
  std::map<int, visualization_msgs::Marker> voxel_markers;
  std::size_t marker_arrays = 0;
  const ros::Subscriber marker_sub = nh.subscribe<visualization_msgs::MarkerArray>(
      kNode + "markers", 1000, [&](const visualization_msgs::MarkerArray::ConstPtr& a) {
        ++marker_arrays;
        for (const auto& m : a->markers) {
          if (m.ns == "voxels" && m.action == visualization_msgs::Marker::ADD) voxel_markers[m.id] = m;
        }
      });
  ASSERT_TRUE(states.waitFor(1, stc_test::kLivenessSeconds));
  // The markers' link is up before anything is spawned: a piece's voxels
  // marker is sent once, in its birth tick.
  ASSERT_TRUE(stc_test::spinUntil([&] { return marker_arrays > 0; }, stc_test::kLivenessSeconds));

  // 30 m from the slab and the first test's pieces; no gravity in this scene.
  const double y = 30.0;
  sphere_tree_collision::Spawn anvil = rockSpawn("anvil", 5, y, 5000.0, 0.0);
  anvil.request.entity.twist.linear.x = -1.0;  // moving: it does not fall asleep before the hit
  sphere_tree_collision::Spawn ball = rockSpawn("ball", 3, y, 2600.0, 1.0);
  ball.request.entity.pose.position.x = -1.5;
  ball.request.entity.pose.position.z = 0.05;
  ball.request.entity.twist.linear.x = 6.0;
  ball.request.entity.twist.angular.z = 1.5;
  ASSERT_TRUE(ros::service::call(kNode + "spawn", anvil));
  ASSERT_TRUE(anvil.response.success) << anvil.response.message;
  ASSERT_TRUE(ros::service::call(kNode + "spawn", ball));
  ASSERT_TRUE(ball.response.success) << ball.response.message;

  const auto is_piece = [](const std::string& name) { return name.rfind("ball/piece", 0) == 0; };
  const auto has = [](const EntityStates& m, const std::function<bool(const std::string&)>& which) {
    return std::any_of(m.names.begin(), m.names.end(), which);
  };
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return std::any_of(states.all.begin(), states.all.end(), [&](const EntityStates& m) { return has(m, is_piece); }); },
      stc_test::kLivenessSeconds))
      << "the ball never broke";
  // Just before and at the break, by stamp: the last states with the ball
  // and the first with its pieces.
  // Copies: states.all grows (and moves) while later waits spin.
  std::optional<EntityStates> birth_msg, before_msg;
  for (const auto& m : states.all) {
    if (has(m, is_piece)) {
      birth_msg = m;
      break;
    }
    if (has(m, [](const std::string& n) { return n == "ball"; })) before_msg = m;
  }
  ASSERT_TRUE(before_msg.has_value()) << "no states with the whole ball";
  const EntityStates* birth = &*birth_msg;
  const EntityStates* before = &*before_msg;
  ASSERT_LT(before->header.stamp, birth->header.stamp);
  EXPECT_FALSE(has(*birth, [](const std::string& n) { return n == "ball"; })) << "the parent is still there";
  // tick_stats of the birth tick (same stamp) counts the break.
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        return std::any_of(stats.all.begin(), stats.all.end(),
                           [&](const auto& s) { return s.header.stamp == birth->header.stamp; });
      },
      stc_test::kLivenessSeconds));
  for (const auto& s : stats.all) {
    if (s.header.stamp == birth->header.stamp) EXPECT_GE(s.fractures, 1u);
  }

  // Masses from ~entities (latched, republished as entities come and go).
  std::map<std::uint32_t, double> mass;
  std::map<std::uint32_t, bool> is_static;
  const auto listed = [&] {
    for (const auto& list : lists.all) {
      for (const auto& e : list.entities) {
        mass[e.id] = e.inertia.m;
        is_static[e.id] = e.is_static;
      }
    }
    for (const std::uint32_t id : birth->ids) {
      if (mass.count(id) == 0) return false;
    }
    return mass.count(ball.response.id) != 0;
  };
  ASSERT_TRUE(stc_test::spinUntil(listed, stc_test::kLivenessSeconds)) << "~entities never listed the pieces";
  const double ball_mass = mass[ball.response.id];
  EXPECT_GT(ball_mass, 0.0);
  EXPECT_GT(mass[anvil.response.id], ball_mass);
  for (const auto& [id, m] : mass) {
    if (is_static[id]) EXPECT_EQ(m, 0.0) << "static entity " << id;
  }

  const auto pair_before = [](const std::string& n) { return n == "ball" || n == "anvil"; };
  const auto pair_after = [&](const std::string& n) { return n == "anvil" || is_piece(n); };
  const Momentum p0 = momentumOf(*before, mass, pair_before);
  const Momentum p1 = momentumOf(*birth, mass, pair_after);
  EXPECT_GT(p0.scale, 0.0);
  EXPECT_LE((p1.p - p0.p).norm(), 1e-9 * p0.scale) << "before " << p0.p.transpose() << ", after " << p1.p.transpose();
  std::vector<std::size_t> pieces;
  double pieces_mass = 0.0;
  for (std::size_t i = 0; i < birth->names.size(); ++i) {
    if (!is_piece(birth->names[i])) continue;
    pieces.push_back(i);
    pieces_mass += mass[birth->ids[i]];
  }
  ASSERT_GE(pieces.size(), 2u);
  EXPECT_NEAR(pieces_mass, ball_mass, 1e-9 * ball_mass);

  // Overlap at birth: each piece's voxels (the voxels marker: surface voxel
  // centres in the piece's frame) placed by its birth pose. Pieces keep the
  // ball's orientation, so their voxels lie on one lattice: in that frame two
  // voxels of different pieces are a whole number of voxels apart, and
  // overlap unless one coordinate differs by a whole voxel.
  const double s = ball.request.entity.voxel_size;
  const auto voxels_of = [&](std::size_t i) -> const visualization_msgs::Marker* {
    const auto it = voxel_markers.find(static_cast<int>(birth->ids[i] & 0x7fffffffu));
    return it == voxel_markers.end() ? nullptr : &it->second;
  };
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return std::all_of(pieces.begin(), pieces.end(), [&](std::size_t i) { return voxels_of(i) != nullptr; }); },
      stc_test::kLivenessSeconds))
      << "no voxels marker for a piece";
  const auto orientation = [&](std::size_t i) {
    const auto& q = birth->poses[i].orientation;
    return Eigen::Quaterniond(q.w, q.x, q.y, q.z);
  };
  const Eigen::Quaterniond r = orientation(pieces[0]);
  std::vector<std::vector<Eigen::Vector3d>> lattice(pieces.size());  // voxel centres / s, in the ball's frame
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const std::size_t i = pieces[k];
    EXPECT_LE(orientation(i).angularDistance(r), 1e-9) << birth->names[i];
    const visualization_msgs::Marker& m = *voxels_of(i);
    EXPECT_EQ(m.header.frame_id, birth->names[i]);
    EXPECT_TRUE(m.frame_locked);
    const Eigen::Vector3d x = vec(birth->poses[i].position);
    for (const auto& c : m.points) lattice[k].push_back(r.conjugate() * (x + orientation(i) * vec(c)) / s);
  }
  std::size_t overlapping = 0, touching = 0, off_lattice = 0;
  for (std::size_t a = 0; a < pieces.size(); ++a) {
    for (std::size_t b = a + 1; b < pieces.size(); ++b) {
      for (const Eigen::Vector3d& va : lattice[a]) {
        for (const Eigen::Vector3d& vb : lattice[b]) {
          const Eigen::Vector3d d = va - vb;
          const Eigen::Vector3d whole = d.array().round().matrix();
          off_lattice += (d - whole).cwiseAbs().maxCoeff() > 1e-6 ? 1 : 0;
          const double apart = whole.cwiseAbs().maxCoeff();
          overlapping += apart < 1.0 ? 1 : 0;
          touching += apart == 1.0 && whole.cwiseAbs().sum() == 1.0 ? 1 : 0;
        }
      }
    }
  }
  // Figures, in the test's XML result.
  testing::Test::RecordProperty("pieces", static_cast<int>(pieces.size()));
  testing::Test::RecordProperty("momentum_change_relative", std::to_string((p1.p - p0.p).norm() / p0.scale));
  testing::Test::RecordProperty("piece_mass_error_relative", std::to_string(std::abs(pieces_mass - ball_mass) / ball_mass));
  testing::Test::RecordProperty("voxel_pairs_touching", static_cast<int>(touching));
  testing::Test::RecordProperty("states_stamps_apart_s", std::to_string((birth->header.stamp - before->header.stamp).toSec()));
  EXPECT_EQ(off_lattice, 0u) << "a piece's voxels are not on the ball's lattice";
  EXPECT_EQ(overlapping, 0u) << "voxels of two pieces overlap at birth";
  EXPECT_GT(touching, 0u) << "no two pieces share a face: the check saw no cut";
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "fracture_test"); }
