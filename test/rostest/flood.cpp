// Flood: 10,000 spawns and then 10,000 despawns on the node's topics, each
// burst published at once, while the test subscribes to every output topic
// (markers, error bounds, contacts, tick_stats, entities, entity states, tf).
// Asserted: no message is dropped or refused (tick_stats' entity count reaches
// exactly 10,000 and then 0, the latched entity list says the same, nothing is
// counted as rejected), and the node's resident set, once the world is empty
// again, is within 1.5 x its level before the flood (issue 47): a state, read
// from /proc/<pid>/status. Waits are liveness bounds. Printed, not asserted:
// the tick time each half took, and the resident set before, full and after.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <ros/master.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/EntityList.h>
#include <sphere_tree_collision/EntityStates.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace {

using sphere_tree_collision::Despawn;
using sphere_tree_collision::SpawnEntity;
using sphere_tree_collision::TickStats;
using stc_test::Recorder;

constexpr int kFlood = 10000;
constexpr double kFloodLiveness = 300.0;  // s: a bound for a hung node only

// The process id of a ROS node, asked of the node itself (its XML-RPC getPid).
int nodePid(const std::string& node) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  args[1] = node;
  if (!ros::master::execute("lookupNode", args, result, payload, true)) return -1;
  const std::string uri = payload;  // http://host:port/
  const std::size_t host_begin = uri.find("//") + 2;
  const std::size_t colon = uri.find(':', host_begin);
  const std::string host = uri.substr(host_begin, colon - host_begin);
  const int port = std::stoi(uri.substr(colon + 1));
  XmlRpc::XmlRpcClient client(host.c_str(), port, "/");
  XmlRpc::XmlRpcValue pid_args, pid_result;
  pid_args[0] = ros::this_node::getName();
  if (!client.execute("getPid", pid_args, pid_result) || pid_result.size() < 3) return -1;
  return static_cast<int>(pid_result[2]);
}

// VmRSS of a process, kB (-1 when unreadable).
long residentKb(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  long value = -1;
  while (status >> key) {
    if (key == "VmRSS:") {
      status >> value;
      return value;
    }
  }
  return -1;
}

SpawnEntity floodCube(int k) {
  SpawnEntity m;
  m.name = "flood_" + std::to_string(k);
  m.preset = "cube";
  m.resolution = 2;
  m.voxel_size = 0.1;
  m.pose.position.x = (k % 100) * 1.0;  // 1 m apart, at rest, no gravity: no contacts
  m.pose.position.y = (k / 100) * 1.0;
  m.pose.orientation.w = 1.0;
  return m;
}

TEST(Flood, TenThousandSpawnsAndDespawnsAreAllApplied) {
  ros::NodeHandle nh;
  // Every output topic subscribed, as a busy rviz and a logger would.
  Recorder<TickStats> stats(nh, "/collision_world/tick_stats", 1000);
  stats.keep_all = true;
  Recorder<sphere_tree_collision::EntityList> entities(nh, "/collision_world/entities", 10);
  Recorder<sphere_tree_collision::EntityStates> states(nh, "/collision_world/entity_states", 10);
  Recorder<sphere_tree_collision::ContactArray> contacts(nh, "/collision_world/contacts", 10);
  Recorder<visualization_msgs::MarkerArray> markers(nh, "/collision_world/markers", 10);
  Recorder<visualization_msgs::MarkerArray> bounds(nh, "/collision_world/error_bounds", 10);
  Recorder<tf2_msgs::TFMessage> tf(nh, "/tf", 10);
  ros::Publisher spawn = nh.advertise<SpawnEntity>("/collision_world/spawn", kFlood);
  ros::Publisher despawn = nh.advertise<Despawn>("/collision_world/despawn", kFlood);
  ASSERT_TRUE(stc_test::spinUntil(
      [&] { return spawn.getNumSubscribers() > 0 && despawn.getNumSubscribers() > 0 && stats.count() > 0; },
      stc_test::kLivenessSeconds));
  // The level before the flood, once every subscriber is connected and a few ticks ran.
  ASSERT_TRUE(stats.waitFor(stats.count() + 30, stc_test::kLivenessSeconds));
  const int pid = nodePid("/collision_world");
  ASSERT_GT(pid, 0);
  const long rss_before = residentKb(pid);
  ASSERT_GT(rss_before, 0);
  const std::uint64_t rejected_before = stats.last.rejected_inputs;

  const std::size_t first_spawn_tick = stats.all.size();
  for (int k = 0; k < kFlood; ++k) spawn.publish(floodCube(k));
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.entities >= kFlood; }, kFloodLiveness))
      << "entities " << stats.last.entities << " of " << kFlood << ", rejected "
      << stats.last.rejected_inputs - rejected_before << ", last: " << stats.last.last_rejection;
  EXPECT_EQ(stats.last.entities, static_cast<unsigned>(kFlood));
  ASSERT_TRUE(stc_test::spinUntil([&] { return entities.last.entities.size() == kFlood; }, stc_test::kLivenessSeconds))
      << "the entity list has " << entities.last.entities.size();
  const long rss_full = residentKb(pid);

  const std::size_t first_despawn_tick = stats.all.size();
  for (int k = 0; k < kFlood; ++k) {
    Despawn d;
    d.name = "flood_" + std::to_string(k);
    despawn.publish(d);
  }
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.entities == 0; }, kFloodLiveness))
      << "entities " << stats.last.entities << " left, rejected " << stats.last.rejected_inputs - rejected_before;
  ASSERT_TRUE(stc_test::spinUntil([&] { return entities.last.entities.empty(); }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats.last.rejected_inputs, rejected_before) << stats.last.last_rejection;
  EXPECT_EQ(stats.last.quarantined_total + stats.last.left_world_total, 0u);
  // Let a few ticks run on the empty world, then compare the resident set.
  ASSERT_TRUE(stats.waitFor(stats.count() + 30, stc_test::kLivenessSeconds));
  const long rss_after = residentKb(pid);
  // What the world held is handed back (WorldNode::releaseFreedMemory): the
  // libraries and the empty world are most of the level before.
  EXPECT_LE(rss_after, rss_before * 3 / 2) << "RSS " << rss_before << " kB before, " << rss_full << " kB full";

  // Figures, not asserts: the tick time each half took, summed over the node's ticks.
  auto tickTime = [&](std::size_t from, std::size_t to) {
    double ms = 0.0;
    for (std::size_t i = from; i < to && i < stats.all.size(); ++i) ms += stats.all[i].total_ms;
    return ms;
  };
  // One past the first tick in [from, to) whose entity count is `n`: the tick the half was applied by.
  auto appliedBy = [&](std::size_t from, std::size_t to, unsigned n) {
    for (std::size_t i = from; i < to; ++i) {
      if (stats.all[i].entities == n) return i + 1;
    }
    return to;
  };
  const std::size_t full_tick = appliedBy(first_spawn_tick, first_despawn_tick, kFlood);
  const std::size_t empty_tick = appliedBy(first_despawn_tick, stats.all.size(), 0);
  std::printf("flood: %d spawns applied over %zu ticks (%.0f ms of tick time), %d despawns over %zu ticks (%.0f ms); "
              "RSS %ld kB before, %ld kB full, %ld kB after; %zu marker arrays, %zu entity states, %zu tf\n",
              kFlood, full_tick - first_spawn_tick, tickTime(first_spawn_tick, full_tick), kFlood,
              empty_tick - first_despawn_tick, tickTime(first_despawn_tick, empty_tick), rss_before, rss_full,
              rss_after, markers.count(), states.count(), tf.count());
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "flood_test"); }
