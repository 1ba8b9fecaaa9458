// Hammer: batches of malformed and extreme messages on spawn, despawn, gaze
// and clicked_point (every numeric field: NaN, infinities, 1e308, subnormals,
// values just past a limit, stamps at the ends of the time range, unknown
// names and frames, oversized strings and grids), interleaved with valid
// spawns, despawns and gazes, while a 200-entity scene runs. Asserted: the
// node keeps ticking (its tick counter advances after every batch), every
// malformed message is counted as rejected by its topic, the entity count is
// the scene plus valid spawns minus valid despawns, and no pose or contact
// published on /tf or /contacts is non-finite. Each wait is a 60 s liveness
// bound: the test judges what arrived, never when.
#include "rostest_util.hpp"

#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/Quarantined.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_msgs/TFMessage.h>

#include <cfloat>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace {

using sphere_tree_collision::Despawn;
using sphere_tree_collision::GazePoint;
using sphere_tree_collision::SpawnEntity;
using sphere_tree_collision::TickStats;
using stc_test::Recorder;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kLiveness = 60.0;  // s: only a bound for a dead node, never a timing assert
constexpr int kBatches = 40;
constexpr int kPerTopicPerBatch = 6;  // malformed; + 1 valid: under the node's gaze queue of 10

// Values no numeric field accepts, whatever its limit.
const std::vector<double> kNonFinite{kNaN, kInf, -kInf};
// Finite but beyond every limit of its field (speed, spin, world extent, density).
const std::vector<double> kHuge{1e308, -1e308, DBL_MAX, 1e300, -1e30};

SpawnEntity validSpawn(const std::string& name, int k) {
  SpawnEntity m;
  m.name = name;
  m.preset = "cube";
  m.resolution = 3;
  m.voxel_size = 0.05;
  m.pose.position.x = 50.0 + (k % 20);  // far from the packed box, at rest: stays
  m.pose.position.y = 50.0 + (k / 20);
  m.pose.orientation.w = 1.0;
  m.density = 1000.0;
  m.restitution = 0.3;
  m.friction = 0.5;
  return m;
}

// Malformed spawns, one edit each; cycled through by the batches.
std::vector<std::function<void(SpawnEntity&)>> spawnKinds() {
  std::vector<std::function<void(SpawnEntity&)>> kinds;
  const auto each = [&](const std::vector<double>& values, auto set) {
    for (double v : values) kinds.push_back([v, set](SpawnEntity& m) { set(m, v); });
  };
  std::vector<double> bad = kNonFinite;
  bad.insert(bad.end(), kHuge.begin(), kHuge.end());
  each(bad, [](SpawnEntity& m, double v) { m.pose.position.x = v; });
  each(bad, [](SpawnEntity& m, double v) { m.pose.position.z = v; });
  each({1.0001e4, -2e4}, [](SpawnEntity& m, double v) { m.pose.position.y = v; });  // past ~world_extent
  each(bad, [](SpawnEntity& m, double v) { m.twist.linear.y = v; });
  each({1001.0}, [](SpawnEntity& m, double v) { m.twist.linear.x = v; });  // past ~max_speed
  each(bad, [](SpawnEntity& m, double v) { m.twist.angular.z = v; });
  each({1001.0}, [](SpawnEntity& m, double v) { m.twist.angular.x = v; });  // past ~max_spin
  // 0 (all four components, density, a preset's voxel_size) is left out: it takes
  // the node's default (issue 50); these are malformed.
  each({kNaN, kInf, 2.0, 1e308, 5e-324}, [](SpawnEntity& m, double v) { m.pose.orientation.w = v; });
  each({kNaN, 5e-324, 1e-310, DBL_MIN, -1.0, 1e-9, 1e308, kInf},
       [](SpawnEntity& m, double v) { m.density = v; });
  each({kNaN, kInf, -1e-9, 1.0000001, 1e308}, [](SpawnEntity& m, double v) { m.restitution = v; });
  each({kNaN, kInf, -1.0, 1e308, 11.0}, [](SpawnEntity& m, double v) { m.friction = v; });
  each({kNaN, kInf, -0.05, 5e-324, 1e-300, 1e308, 2e3}, [](SpawnEntity& m, double v) { m.voxel_size = v; });
  kinds.push_back([](SpawnEntity& m) { m.resolution = 4294967295u; });
  kinds.push_back([](SpawnEntity& m) { m.resolution = 5000; });
  kinds.push_back([](SpawnEntity& m) { m.resolution = 200; });  // 8M voxels: past ~max_voxels
  kinds.push_back([](SpawnEntity& m) { m.preset = "dodecahedron"; });
  kinds.push_back([](SpawnEntity& m) { m.preset = std::string(10000, 'x'); });
  kinds.push_back([](SpawnEntity& m) { m.preset.clear(); });
  kinds.push_back([](SpawnEntity& m) { m.dims = {2, 2, 2}; m.occupancy.assign(8, 1); });  // preset and grid
  kinds.push_back([](SpawnEntity& m) { m.preset.clear(); m.dims = {4294967295u, 1, 1}; });
  kinds.push_back([](SpawnEntity& m) { m.preset.clear(); m.dims = {2, 2, 2}; m.occupancy.assign(7, 1); });
  kinds.push_back([](SpawnEntity& m) { m.preset.clear(); m.dims = {2, 2, 2}; m.occupancy.assign(8, 0); });
  kinds.push_back([](SpawnEntity& m) { m.preset.clear(); m.dims = {1000, 1000, 1000}; m.occupancy.assign(100, 1); });
  kinds.push_back([](SpawnEntity& m) { m.name = std::string(10000, 'n'); });
  kinds.push_back([](SpawnEntity& m) { m.name = "bad name/with\nbreaks"; });
  kinds.push_back([](SpawnEntity& m) { m.name = "entity_12"; });
  kinds.push_back([](SpawnEntity& m) { m.color.r = std::nanf(""); m.color.a = 1.0f; });
  kinds.push_back([](SpawnEntity& m) { m.color.g = -1.0f; m.color.a = 1.0f; });
  return kinds;
}

std::vector<std::function<void(Despawn&)>> despawnKinds() {
  return {
      [](Despawn& d) { d.id = 4294967295u; },
      [](Despawn& d) { d.id = 10000000; },
      [](Despawn& d) { d.name = "nobody"; },
      [](Despawn& d) { d.name = std::string(10000, 'z'); },
      [](Despawn& d) { d.name = "not/a frame"; },
      [](Despawn& d) { d.name = "ok_never_spawned"; },
  };
}

// Malformed gazes; `now` is the current time in seconds.
std::vector<std::function<void(GazePoint&, double now)>> gazeKinds() {
  std::vector<std::function<void(GazePoint&, double)>> kinds;
  for (double v : {kNaN, kInf, -kInf, 1e308, -1e308, -1.0, 5000.0, -5e-324}) {
    kinds.push_back([v](GazePoint& g, double) { g.x = v; });
    kinds.push_back([v](GazePoint& g, double) { g.y = v; });
  }
  kinds.push_back([](GazePoint& g, double) { g.header.stamp.sec = 4294967295u; g.header.stamp.nsec = 999999999u; });
  kinds.push_back([](GazePoint& g, double) { g.header.stamp.sec = 4294967295u; g.header.stamp.nsec = 4294967295u; });
  kinds.push_back([](GazePoint& g, double) { g.header.stamp.sec = 1; g.header.stamp.nsec = 0; });
  kinds.push_back([](GazePoint& g, double) { g.header.stamp.sec = 0; g.header.stamp.nsec = 1; });
  kinds.push_back([](GazePoint& g, double now) { g.header.stamp.fromSec(now - 30.0); });
  kinds.push_back([](GazePoint& g, double now) { g.header.stamp.fromSec(now + 30.0); });
  return kinds;
}

std::vector<std::function<void(geometry_msgs::PointStamped&)>> clickedKinds() {
  std::vector<std::function<void(geometry_msgs::PointStamped&)>> kinds;
  for (double v : {kNaN, kInf, -kInf, 1e308, -1e300, 2e4}) {
    kinds.push_back([v](geometry_msgs::PointStamped& p) { p.point.x = v; });
    kinds.push_back([v](geometry_msgs::PointStamped& p) { p.point.z = v; });
  }
  kinds.push_back([](geometry_msgs::PointStamped& p) { p.point.y = -1.5e4; });  // past ~world_extent
  kinds.push_back([](geometry_msgs::PointStamped& p) { p.header.frame_id = "map"; });
  kinds.push_back([](geometry_msgs::PointStamped& p) { p.header.frame_id = std::string(10000, 'f'); });
  return kinds;
}

bool finiteTransform(const geometry_msgs::Transform& t) {
  return std::isfinite(t.translation.x) && std::isfinite(t.translation.y) && std::isfinite(t.translation.z) &&
         std::isfinite(t.rotation.x) && std::isfinite(t.rotation.y) && std::isfinite(t.rotation.z) &&
         std::isfinite(t.rotation.w);
}

bool finiteContact(const sphere_tree_collision::Contact& c) {
  return std::isfinite(c.point.x) && std::isfinite(c.point.y) && std::isfinite(c.point.z) &&
         std::isfinite(c.normal.x) && std::isfinite(c.normal.y) && std::isfinite(c.normal.z) &&
         std::isfinite(c.depth) && std::isfinite(c.gap_bound) && std::isfinite(c.priority);
}

TEST(Hammer, MalformedFloodIsRejectedByTopicWhileTheWorldRuns) {
  ros::NodeHandle nh;
  ros::Publisher spawn = nh.advertise<SpawnEntity>("/collision_world/spawn", 1000);
  ros::Publisher despawn = nh.advertise<Despawn>("/collision_world/despawn", 1000);
  ros::Publisher gaze = nh.advertise<GazePoint>("/collision_world/gaze", 1000);
  ros::Publisher clicked = nh.advertise<geometry_msgs::PointStamped>("/clicked_point", 1000);
  Recorder<TickStats> stats(nh, "/collision_world/tick_stats");
  std::size_t tf_seen = 0, tf_non_finite = 0, contacts_seen = 0, contacts_non_finite = 0;
  ros::Subscriber tf_sub = nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const auto& m) {
    for (const auto& t : m->transforms) {
      ++tf_seen;
      tf_non_finite += finiteTransform(t.transform) ? 0 : 1;
    }
  });
  ros::Subscriber contacts_sub = nh.subscribe<sphere_tree_collision::ContactArray>("/collision_world/contacts", 100, [&](const auto& m) {
    for (const auto& c : m->contacts) {
      ++contacts_seen;
      contacts_non_finite += finiteContact(c) ? 0 : 1;
    }
  });
  ASSERT_TRUE(stc_test::spinUntil(
      [&] {
        return spawn.getNumSubscribers() > 0 && despawn.getNumSubscribers() > 0 && gaze.getNumSubscribers() > 0 &&
               clicked.getNumSubscribers() > 0 && stats.count() > 0;
      },
      kLiveness));
  const TickStats start = stats.last;
  ASSERT_GE(start.entities, 200u) << "the packed box: 200 movers and its walls";

  const auto spawn_kinds = spawnKinds();
  const auto despawn_kinds = despawnKinds();
  const auto gaze_kinds = gazeKinds();
  const auto clicked_kinds = clickedKinds();
  std::uint64_t sent[4] = {0, 0, 0, 0};  // malformed, per topic: spawn, despawn, gaze, clicked_point
  int valid_spawns = 0, valid_despawns = 0, valid_gazes = 0;
  std::vector<std::string> spawned;  // valid spawns confirmed in the world, not yet despawned

  for (int batch = 0; batch < kBatches; ++batch) {
    SCOPED_TRACE("batch " + std::to_string(batch));
    const std::uint64_t tick_before = stats.last.tick;
    const double now = ros::Time::now().toSec();
    for (int i = 0; i < kPerTopicPerBatch; ++i) {
      const std::size_t k = static_cast<std::size_t>(batch * kPerTopicPerBatch + i);
      SpawnEntity s = validSpawn("", static_cast<int>(k));
      spawn_kinds[k % spawn_kinds.size()](s);
      spawn.publish(s);
      Despawn d;
      despawn_kinds[k % despawn_kinds.size()](d);
      despawn.publish(d);
      GazePoint g;
      g.header.stamp.fromSec(now);
      g.x = 640;
      g.y = 360;
      gaze_kinds[k % gaze_kinds.size()](g, now);
      gaze.publish(g);
      geometry_msgs::PointStamped p;
      p.header.frame_id = "world";
      clicked_kinds[k % clicked_kinds.size()](p);
      clicked.publish(p);
      for (std::uint64_t& n : sent) ++n;
    }
    // Valid input interleaved: a spawn, a despawn of an earlier one, a gaze.
    const std::string name = "ok_" + std::to_string(batch);
    spawn.publish(validSpawn(name, batch));
    ++valid_spawns;
    if (batch % 3 == 2 && !spawned.empty()) {
      Despawn d;
      d.name = spawned.front();
      despawn.publish(d);
      spawned.erase(spawned.begin());
      ++valid_despawns;
    }
    GazePoint g;  // stamp 0: "now" to the node, so a late arrival is not a stale rejection
    g.x = 320 + 10 * batch;
    g.y = 360;
    gaze.publish(g);
    ++valid_gazes;

    // Everything sent so far is counted, the world holds what it should, and it ticked on.
    const auto caught_up = [&] {
      const TickStats& s = stats.last;
      const std::uint64_t removed = (s.quarantined_total - start.quarantined_total) + (s.left_world_total - start.left_world_total);
      return s.rejected_spawn - start.rejected_spawn == sent[0] &&
             s.rejected_despawn - start.rejected_despawn == sent[1] &&
             s.rejected_gaze - start.rejected_gaze == sent[2] &&
             s.rejected_clicked_point - start.rejected_clicked_point == sent[3] &&
             s.entities + removed == start.entities + valid_spawns - valid_despawns && s.tick > tick_before;
    };
    ASSERT_TRUE(stc_test::spinUntil(caught_up, kLiveness))
        << "tick " << stats.last.tick << " (was " << tick_before << "), rejected spawn/despawn/gaze/clicked "
        << stats.last.rejected_spawn - start.rejected_spawn << "/" << stats.last.rejected_despawn - start.rejected_despawn
        << "/" << stats.last.rejected_gaze - start.rejected_gaze << "/"
        << stats.last.rejected_clicked_point - start.rejected_clicked_point << " of " << sent[0] << " each, entities "
        << stats.last.entities << ", last rejection '" << stats.last.last_rejection << "'";
    spawned.push_back(name);
  }

  const TickStats& end = stats.last;
  const std::uint64_t malformed = sent[0] + sent[1] + sent[2] + sent[3];
  EXPECT_GE(malformed, 900u);
  EXPECT_EQ(end.rejected_inputs - start.rejected_inputs, malformed) << "valid input is never counted as rejected";
  EXPECT_EQ(end.callback_errors, 0u) << "every malformed message was rejected as input, nothing escaped";
  EXPECT_EQ(end.quarantined_total, 0u) << "the valid scene and spawns never leave the limits";
  EXPECT_EQ(end.entities, start.entities + valid_spawns - valid_despawns);
  EXPECT_GT(valid_gazes, 0);
  // The world kept publishing poses, and none was non-finite.
  const std::size_t tf_before = tf_seen;
  EXPECT_TRUE(stc_test::spinUntil([&] { return tf_seen > tf_before && contacts_seen > 0; }, kLiveness));
  EXPECT_EQ(tf_non_finite, 0u) << "of " << tf_seen << " transforms";
  EXPECT_EQ(contacts_non_finite, 0u) << "of " << contacts_seen << " contacts";
}

TEST(Hammer, ABodyLeavingTheWorldIsRemovedAndReportedByName) {
  ros::NodeHandle nh;
  ros::Publisher spawn = nh.advertise<SpawnEntity>("/collision_world/spawn", 10);
  Recorder<TickStats> stats(nh, "/collision_world/tick_stats");
  Recorder<sphere_tree_collision::Quarantined> quarantined(nh, "/collision_world/quarantined");
  quarantined.keep_all = true;
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return spawn.getNumSubscribers() > 0 && stats.count() > 0 && quarantined.sub_.getNumPublishers() > 0; },
      kLiveness));
  const TickStats before = stats.last;
  // 0.5 m inside ~world_extent (10 km), flying out at 100 m/s: gone within a few ticks.
  SpawnEntity m = validSpawn("escaper", 0);
  m.pose.position.x = 9999.5;
  m.twist.linear.x = 100.0;
  spawn.publish(m);
  ASSERT_TRUE(stc_test::spinUntil([&] { return !quarantined.all.empty(); }, kLiveness));
  EXPECT_EQ(quarantined.all[0].frame, "escaper");
  EXPECT_EQ(quarantined.all[0].reason, "left the world");
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.left_world_total == before.left_world_total + 1; }, kLiveness));
  EXPECT_EQ(stats.last.entities, before.entities) << "removed from the world";
  EXPECT_EQ(stats.last.quarantined_total, before.quarantined_total) << "leaving is not an error";
  EXPECT_EQ(stats.last.last_quarantine, "escaper: left the world");
  EXPECT_EQ(stats.last.rejected_spawn, before.rejected_spawn);
  // Its name is free again: the node forgot it as well.
  m.pose.position.x = 60.0;
  m.twist.linear.x = 0.0;
  spawn.publish(m);
  EXPECT_TRUE(stc_test::spinUntil([&] { return stats.last.entities == before.entities + 1; }, kLiveness));
  EXPECT_EQ(stats.last.rejected_spawn, before.rejected_spawn);
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "hammer_test"); }
