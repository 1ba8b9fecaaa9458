// The world node's services: every answer is checked (success, id, frame, the
// field a failure names), and what it did is checked in ~entities, tf and
// tick_stats. Failures must change nothing.
#include "rostest_util.hpp"

#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <sphere_tree_collision/DespawnEntity.h>
#include <sphere_tree_collision/EntityList.h>
#include <sphere_tree_collision/Spawn.h>
#include <sphere_tree_collision/Step.h>
#include <sphere_tree_collision/TickStats.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <thread>

namespace {

using sphere_tree_collision::EntityList;
using sphere_tree_collision::Spawn;
using stc_test::Recorder;

const std::string kNode = "/collision_world/";

class Services : public testing::Test {
 protected:
  Services() : stats_(nh_, "/collision_world/tick_stats"), list_(nh_, kNode + "entities"), listener_(tf_, nh_, false) {
    for (const char* name : {"spawn", "despawn", "clear", "pause", "unpause", "step", "reset"}) {
      EXPECT_TRUE(ros::service::waitForService(kNode + name, ros::Duration(stc_test::kLivenessSeconds))) << name;
    }
    EXPECT_TRUE(stc_test::spinUntil([&] { return list_.count() > 0 && stats_.count() > 0; }, stc_test::kLivenessSeconds));
  }

  template <typename Srv>
  Srv call(const std::string& name, Srv srv = Srv()) {
    EXPECT_TRUE(ros::service::call(kNode + name, srv)) << name;
    return srv;
  }
  std_srvs::Trigger trigger(const std::string& name) { return call<std_srvs::Trigger>(name); }

  static Spawn cube(const std::string& name, double x) {
    Spawn s;
    s.request.entity.name = name;
    s.request.entity.preset = "cube";
    s.request.entity.resolution = 4;
    s.request.entity.voxel_size = 0.05;
    s.request.entity.pose.position.x = x;
    s.request.entity.pose.position.z = 5.0;
    s.request.entity.pose.orientation.w = 1.0;
    s.request.entity.density = 1000.0;
    s.request.entity.restitution = 0.3;
    s.request.entity.friction = 0.5;
    return s;
  }

  // A spawn in a frame the node's tf may not know yet (stamp 0: its latest),
  // asked again while a new listener of the node's connects.
  Spawn spawnOnceTfKnows(Spawn s) {
    EXPECT_TRUE(stc_test::spinUntil([&] {
      s = call("spawn", s);
      return s.response.success;
    }, stc_test::kLivenessSeconds)) << s.response.message;
    return s;
  }

  // The next ~entities list for which `holds` is true.
  testing::AssertionResult waitForList(const std::function<bool(const EntityList&)>& holds) {
    if (stc_test::spinUntil([&] { return holds(list_.last); }, stc_test::kLivenessSeconds)) return testing::AssertionSuccess();
    return testing::AssertionFailure() << "~entities holds " << list_.last.entities.size() << " entities";
  }
  static const sphere_tree_collision::EntityInfo* find(const EntityList& list, std::uint32_t id) {
    for (const auto& e : list.entities) {
      if (e.id == id) return &e;
    }
    return nullptr;
  }
  static std::set<std::string> frames(const EntityList& list) {
    std::set<std::string> out;
    for (const auto& e : list.entities) out.insert(e.frame);
    return out;
  }

  // Pauses and steps one tick, so tick_stats shows the world as the requests left it.
  sphere_tree_collision::TickStats statsAfterOneStep() {
    if (!stats_.last.paused) EXPECT_TRUE(trigger("pause").response.success);
    sphere_tree_collision::Step step;
    step.request.ticks = 1;
    step = call("step", step);
    EXPECT_TRUE(step.response.success) << step.response.message;
    EXPECT_TRUE(stc_test::spinUntil([&] { return stats_.last.tick >= step.response.tick; }, stc_test::kLivenessSeconds));
    EXPECT_EQ(stats_.last.tick, step.response.tick);
    return stats_.last;
  }

  ros::NodeHandle nh_;
  Recorder<sphere_tree_collision::TickStats> stats_;
  Recorder<EntityList> list_;
  tf2_ros::Buffer tf_;
  tf2_ros::TransformListener listener_;
};

TEST_F(Services, SpawnAnswersIdAndFrameAndTheListShowsIt) {
  Spawn named = call("spawn", cube("box_a", 1.0));
  ASSERT_TRUE(named.response.success) << named.response.message;
  EXPECT_EQ(named.response.message, "");
  EXPECT_EQ(named.response.frame_id, "box_a");
  Spawn unnamed = call("spawn", cube("", 2.0));
  ASSERT_TRUE(unnamed.response.success) << unnamed.response.message;
  EXPECT_NE(unnamed.response.id, named.response.id);
  EXPECT_EQ(unnamed.response.frame_id, "entity_" + std::to_string(unnamed.response.id));

  ASSERT_TRUE(waitForList([&](const EntityList& l) { return find(l, unnamed.response.id) != nullptr; }));
  const auto* a = find(list_.last, named.response.id);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->name, "box_a");
  EXPECT_EQ(a->frame, "box_a");
  EXPECT_EQ(a->shape.rfind("cube/r4/", 0), 0u) << a->shape;
  EXPECT_FALSE(a->is_static);
  const auto* b = find(list_.last, unnamed.response.id);
  EXPECT_EQ(b->name, "");
  EXPECT_EQ(b->shape, a->shape);  // equal presets share one shape
  // The start scene is listed too, with the static flag.
  bool floor_static = false;
  for (const auto& e : list_.last.entities) floor_static |= e.name == "floor" && e.is_static;
  EXPECT_TRUE(floor_static);
}

TEST_F(Services, SpawnInAnotherFrameIsResolvedByTf) {
  // shelf: 1, 2, 3 m from the world origin, turned 90 degrees about z.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  geometry_msgs::TransformStamped shelf;
  shelf.header.stamp = ros::Time::now();
  shelf.header.frame_id = "world";
  shelf.child_frame_id = "shelf";
  shelf.transform.translation.x = 1.0;
  shelf.transform.translation.y = 2.0;
  shelf.transform.translation.z = 3.0;
  shelf.transform.rotation.z = std::sin(M_PI / 4);
  shelf.transform.rotation.w = std::cos(M_PI / 4);
  broadcaster.sendTransform(shelf);

  Spawn s = cube("on_shelf", 0.5);  // (0.5, 0, 5) in shelf: (1, 2.5, 8) in the world
  s.request.header.frame_id = "shelf";
  // The node waits 1 s for tf to know the frame; its listener is new at the
  // first such call, and a loaded machine may take longer to connect it. A
  // refusal changes nothing, so the call is made again until tf knows.
  Spawn answered = s;
  ASSERT_TRUE(stc_test::spinUntil([&] {
    answered = call("spawn", s);
    return answered.response.success || answered.response.message.rfind("header.frame_id: ", 0) != 0;
  }, stc_test::kLivenessSeconds)) << answered.response.message;
  s = answered;
  ASSERT_TRUE(s.response.success) << s.response.message;
  EXPECT_EQ(s.response.frame_id, "on_shelf");
  // Paused, the entity stays where it was put; tf shows it there.
  statsAfterOneStep();
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf_.canTransform("world", "on_shelf", ros::Time(0)); }, stc_test::kLivenessSeconds));
  const auto t = tf_.lookupTransform("world", "on_shelf", ros::Time(0));
  EXPECT_NEAR(t.transform.translation.x, 1.0, 1e-9);
  EXPECT_NEAR(t.transform.translation.y, 2.5, 1e-9);
  EXPECT_NEAR(t.transform.translation.z, 8.0, 1e-9);
  EXPECT_NEAR(std::abs(t.transform.rotation.z), std::sin(M_PI / 4), 1e-9);  // the shelf's turn
  // An orientation left out (all four zero) is the identity in the request's
  // frame: the shelf's turn, not the world's.
  Spawn turned = cube("turned_by_shelf", -0.5);
  turned.request.header.frame_id = "shelf";
  turned.request.entity.pose.orientation.w = 0.0;
  turned = call("spawn", turned);
  ASSERT_TRUE(turned.response.success) << turned.response.message;
  statsAfterOneStep();
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf_.canTransform("world", "turned_by_shelf", ros::Time(0)); }, stc_test::kLivenessSeconds));
  const auto r = tf_.lookupTransform("world", "turned_by_shelf", ros::Time(0)).transform.rotation;
  EXPECT_NEAR(std::abs(r.z), std::sin(M_PI / 4), 1e-9);
  EXPECT_NEAR(std::abs(r.w), std::cos(M_PI / 4), 1e-9);

  Spawn unknown = cube("nowhere", 0.0);
  unknown.request.header.frame_id = "no_such_frame";
  unknown = call("spawn", unknown);
  EXPECT_FALSE(unknown.response.success);
  EXPECT_EQ(unknown.response.message.rfind("header.frame_id: ", 0), 0u) << unknown.response.message;
  // Once the node's listener has had its first second, a frame tf never
  // heard of is refused by name, without waiting for it on the node's spinner.
  Spawn refused = unknown;
  ASSERT_TRUE(stc_test::spinUntil([&] {
    refused = call("spawn", unknown);
    return refused.response.message == "header.frame_id: tf knows no frame \"no_such_frame\"";
  }, stc_test::kLivenessSeconds)) << refused.response.message;
  EXPECT_FALSE(refused.response.success);
  EXPECT_TRUE(trigger("unpause").response.success);
}

// ~spawn waits for tf on a thread of its own: while a spawn waits for its
// stamp, the world ticks on. A spawn on the drifter (a frame the node itself
// sends on /tf, one transform a tick) stamped 2 s ahead can only be answered
// by a node that goes on ticking while the call waits: one whose ticks
// stood still would never send the drifter at that stamp.
TEST_F(Services, SpawnWaitingForTfLeavesTheTicksRunning) {
  EXPECT_TRUE(trigger("unpause").response.success);
  // First the node's tf learns the frame (stamp 0: its latest; asked again
  // while a new listener of the node's connects).
  Spawn first = cube("rider_1", 0.0);
  first.request.header.frame_id = "drifter";
  ASSERT_TRUE(spawnOnceTfKnows(first).response.success);

  Spawn ahead = cube("rider_2", 0.0);  // 5 m above the drifter
  ahead.request.header.frame_id = "drifter";
  const ros::Time stamp = ros::Time::now() + ros::Duration(2.0);
  ahead.request.header.stamp = stamp;
  Spawn answered;
  std::atomic<bool> done{false};
  std::thread caller([&, ahead] {
    answered = call("spawn", ahead);
    done = true;
  });
  const bool returned = stc_test::spinUntil([&] { return done.load(); }, stc_test::kLivenessSeconds);
  caller.join();
  ASSERT_TRUE(returned);
  ASSERT_TRUE(answered.response.success) << answered.response.message;
  EXPECT_EQ(answered.response.frame_id, "rider_2");
  // Where the drifter was at the stamp, 5 m up: the rider does not move (no gravity, no twist).
  ASSERT_TRUE(stc_test::spinUntil([&] {
    return tf_.canTransform("world", "drifter", stamp) && tf_.canTransform("world", "rider_2", ros::Time(0));
  }, stc_test::kLivenessSeconds));
  const auto drifter = tf_.lookupTransform("world", "drifter", stamp);
  const auto rider = tf_.lookupTransform("world", "rider_2", ros::Time(0));
  EXPECT_NEAR(rider.transform.translation.x, drifter.transform.translation.x, 1e-9);
  EXPECT_NEAR(rider.transform.translation.y, drifter.transform.translation.y, 1e-9);
  EXPECT_NEAR(rider.transform.translation.z, drifter.transform.translation.z + 5.0, 1e-9);
}

TEST_F(Services, SpawnFailuresNameTheFieldAndChangeNothing) {
  const std::uint32_t before = statsAfterOneStep().entities;
  const auto expectRefused = [&](Spawn s, const std::string& field) {
    s = call("spawn", s);
    EXPECT_FALSE(s.response.success) << field;
    EXPECT_EQ(s.response.id, 0u);
    EXPECT_EQ(s.response.message.rfind(field + ": ", 0), 0u) << "expected " << field << ", got " << s.response.message;
  };
  Spawn s = cube("bad", 0.0);
  s.request.entity.density = -1.0;
  expectRefused(s, "entity.density");
  s = cube("bad", 0.0);
  s.request.entity.twist.linear.x = std::numeric_limits<double>::quiet_NaN();
  expectRefused(s, "entity.twist.linear");
  s = cube("bad", 0.0);
  s.request.entity.pose.orientation.w = 2.0;
  expectRefused(s, "entity.pose.orientation");
  s = cube("bad", 0.0);
  s.request.entity.preset = "teapot";
  expectRefused(s, "entity.preset");
  s = cube("drifter", 0.0);  // the scene's
  expectRefused(s, "entity.name");
  s = cube("bad name", 0.0);
  expectRefused(s, "entity.name");
  s = cube("bad", 0.0);
  s.request.entity.restitution = 1.5;
  expectRefused(s, "entity.restitution");
  // 0 takes a default; negative and NaN values are still refused by field.
  s = cube("bad", 0.0);
  s.request.entity.voxel_size = -0.05;
  expectRefused(s, "entity.voxel_size");
  s = cube("bad", 0.0);
  s.request.entity.voxel_size = std::numeric_limits<double>::quiet_NaN();
  expectRefused(s, "entity.voxel_size");
  s = cube("bad", 0.0);
  s.request.entity.density = std::numeric_limits<double>::quiet_NaN();
  expectRefused(s, "entity.density");
  s = cube("bad", 0.0);
  s.request.entity.friction = -0.5;
  expectRefused(s, "entity.friction");
  EXPECT_EQ(statsAfterOneStep().entities, before);
  EXPECT_EQ(stats_.last.rejected_spawn, 0u);  // the topic's counter: services answer instead
  EXPECT_TRUE(trigger("unpause").response.success);
}

// Issue 50: the README's shortest spawn. density, resolution, voxel_size and
// the orientation left at 0 take ~default_density (1000), ~default_resolution
// (8), ~default_voxel_size (0.05) and the identity; restitution and friction
// 0 are real values. The shape key says the defaults were used.
TEST_F(Services, TheShortestSpawnTakesTheDefaults) {
  Spawn s;
  s.request.entity.name = "r1";
  s.request.entity.preset = "rock";
  s.request.entity.pose.position.z = 2.0;
  s = call("spawn", s);
  ASSERT_TRUE(s.response.success) << s.response.message;
  EXPECT_EQ(s.response.frame_id, "r1");
  ASSERT_TRUE(waitForList([&](const EntityList& l) { return find(l, s.response.id) != nullptr; }));
  const auto* r1 = find(list_.last, s.response.id);
  EXPECT_EQ(r1->shape, "rock/r8/v0.05/s0");
  // The same rock, all fields given: the same shape and the same mass.
  Spawn full = s;
  full.request.entity.name = "r1_full";
  full.request.entity.resolution = 8;
  full.request.entity.voxel_size = 0.05;
  full.request.entity.density = 1000.0;
  full.request.entity.pose.orientation.w = 1.0;
  full.request.entity.pose.position.x = 3.0;
  full = call("spawn", full);
  ASSERT_TRUE(full.response.success) << full.response.message;
  ASSERT_TRUE(waitForList([&](const EntityList& l) { return find(l, full.response.id) != nullptr; }));
  const auto* a = find(list_.last, s.response.id);
  const auto* b = find(list_.last, full.response.id);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->shape, b->shape);
  EXPECT_GT(a->inertia.m, 0.0);
  EXPECT_DOUBLE_EQ(a->inertia.m, b->inertia.m);
}

// Issue 47: a stamp at the end of ROS time, on a moving frame (the drifter,
// sent by the node each tick), is refused naming header.stamp, not with tf's
// "Duration is out of dual 32-bit range".
TEST_F(Services, AStampAtTheEndOfTimeIsRefusedByName) {
  EXPECT_TRUE(trigger("unpause").response.success);
  Spawn known = cube("stamp_rider", 0.0);
  known.request.header.frame_id = "drifter";
  ASSERT_TRUE(spawnOnceTfKnows(known).response.success);
  Spawn s = cube("stamp_end", 0.0);
  s.request.header.frame_id = "drifter";
  s.request.header.stamp.sec = 4294967295u;
  s.request.header.stamp.nsec = 999999999u;
  s = call("spawn", s);
  EXPECT_FALSE(s.response.success);
  EXPECT_EQ(s.response.message.rfind("header.stamp: ", 0), 0u) << s.response.message;
  EXPECT_EQ(s.response.id, 0u);
}

// Issue 47 item 4: ~entities goes out at most once every round(~rate /
// ~entities_rate) ticks (30 / 10: 3 here), however fast the world changes. A
// burst of ~spawn calls, each of which used to send a whole list, costs one
// list per period. Judged by tick numbers (tick_stats), not by time.
TEST_F(Services, TheEntityListKeepsItsRateUnderABurstOfSpawns) {
  EXPECT_TRUE(trigger("unpause").response.success);
  const std::uint64_t first_tick = stats_.last.tick;
  const std::size_t lists_before = list_.count();
  constexpr int kSpawns = 60;
  std::uint32_t last_id = 0;
  for (int i = 0; i < kSpawns; ++i) {
    const Spawn s = call("spawn", cube("burst_" + std::to_string(i), 10.0 + i));
    ASSERT_TRUE(s.response.success) << s.response.message;
    last_id = s.response.id;
  }
  ASSERT_TRUE(waitForList([&](const EntityList& l) { return find(l, last_id) != nullptr; }));
  const std::uint64_t ticks = stats_.last.tick - first_tick;
  const std::size_t lists = list_.count() - lists_before;
  EXPECT_LE(lists, ticks / 3 + 2) << lists << " lists over " << ticks << " ticks for " << kSpawns << " spawns";
}

TEST_F(Services, DespawnByNameAndIdAndItsFailures) {
  Spawn a = call("spawn", cube("gone_by_name", 3.0));
  Spawn b = call("spawn", cube("gone_by_id", 4.0));
  ASSERT_TRUE(a.response.success && b.response.success);
  sphere_tree_collision::DespawnEntity d;
  d.request.name = "gone_by_name";
  d = call("despawn", d);
  EXPECT_TRUE(d.response.success) << d.response.message;
  d = sphere_tree_collision::DespawnEntity();
  d.request.id = b.response.id;
  d = call("despawn", d);
  EXPECT_TRUE(d.response.success) << d.response.message;
  EXPECT_TRUE(waitForList([&](const EntityList& l) {
    return find(l, a.response.id) == nullptr && find(l, b.response.id) == nullptr;
  }));

  d = sphere_tree_collision::DespawnEntity();
  d.request.id = b.response.id;  // already gone
  d = call("despawn", d);
  EXPECT_FALSE(d.response.success);
  EXPECT_EQ(d.response.message.rfind("id: ", 0), 0u) << d.response.message;
  d = sphere_tree_collision::DespawnEntity();
  d.request.name = "never_was";
  d = call("despawn", d);
  EXPECT_FALSE(d.response.success);
  EXPECT_EQ(d.response.message.rfind("name: ", 0), 0u) << d.response.message;
}

TEST_F(Services, PauseStepUnpause) {
  sphere_tree_collision::Step step;
  step.request.ticks = 3;
  if (stats_.last.paused) trigger("unpause");
  step = call("step", step);
  EXPECT_FALSE(step.response.success);  // not paused
  EXPECT_EQ(step.response.message.rfind("ticks: ", 0), 0u) << step.response.message;

  ASSERT_TRUE(trigger("pause").response.success);
  EXPECT_TRUE(trigger("pause").response.success);  // pausing twice is no error
  step.request.ticks = 0;
  step = call("step", step);
  EXPECT_FALSE(step.response.success);
  EXPECT_EQ(step.response.message.rfind("ticks: ", 0), 0u) << step.response.message;

  step.request.ticks = 3;
  step = call("step", step);
  ASSERT_TRUE(step.response.success) << step.response.message;
  const std::uint64_t reached = step.response.tick;
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.tick >= reached; }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats_.last.tick, reached);
  EXPECT_TRUE(stats_.last.paused);
  // Stopped exactly there: the next step starts from `reached`.
  step.request.ticks = 2;
  step = call("step", step);
  ASSERT_TRUE(step.response.success);
  EXPECT_EQ(step.response.tick, reached + 2);
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.tick >= reached + 2; }, stc_test::kLivenessSeconds));
  EXPECT_EQ(stats_.last.tick, reached + 2);

  ASSERT_TRUE(trigger("unpause").response.success);
  ASSERT_TRUE(stc_test::spinUntil([&] { return stats_.last.tick > reached + 3; }, stc_test::kLivenessSeconds));
  EXPECT_FALSE(stats_.last.paused);
}

TEST_F(Services, ClearThenResetBringsBackTheStartScene) {
  Spawn extra = call("spawn", cube("extra", 6.0));
  ASSERT_TRUE(extra.response.success);
  ASSERT_TRUE(trigger("clear").response.success);
  EXPECT_TRUE(waitForList([](const EntityList& l) { return l.entities.empty(); }));
  EXPECT_EQ(statsAfterOneStep().entities, 0u);

  ASSERT_TRUE(trigger("reset").response.success);
  EXPECT_TRUE(waitForList([](const EntityList& l) { return l.entities.size() == 2; }));
  EXPECT_EQ(frames(list_.last), (std::set<std::string>{"floor", "drifter"}));
  // The drifter is back at its start: (0, 0, 2) after one step of 1/30 s at 0.5 m/s.
  const ros::Time stepped = statsAfterOneStep().header.stamp;
  EXPECT_EQ(stats_.last.entities, 2u);
  // tf at that tick's stamp (a later message for the frame cannot hide it).
  ASSERT_TRUE(stc_test::spinUntil([&] { return tf_.canTransform("world", "drifter", stepped); }, stc_test::kLivenessSeconds));
  const auto t = tf_.lookupTransform("world", "drifter", stepped);
  EXPECT_NEAR(t.transform.translation.x, 0.5 / 30.0, 1e-9);
  EXPECT_NEAR(t.transform.translation.z, 2.0, 1e-9);
  EXPECT_TRUE(trigger("unpause").response.success);
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "services_test"); }
