// Accuracy of collision_world_node against FCL, over ROS (issue 5, rostest 3).
//
// accuracy.test runs two world nodes on an empty scene, in namespaces
// "unlimited" (no budget) and "tight" (a few sphere tests per tick, unresolved
// pairs accepted). This node owns the scene: it spawns the same entities into
// both through `spawn`, learns each one's id from the tf frame that appears
// (entity_<id>), and builds the same shape locally (stc::addRequest, the
// node's own path) as an FCL mesh. It then records `contacts` and `tf` and,
// for every tick whose contacts and tf share a stamp, checks with FCL at those
// poses:
//   unlimited: every pair FCL finds colliding has a contact, all resolved;
//   both:      every contact's gap_bound >= the true gap (FCL distance);
//   tight:     under policy accept no FCL-colliding pair is missing either.
// It prints the false-positive rate and the mean true gap of the contacts.
//
// The nodes run with ~response false: the response's position correction
// moves bodies after the narrow phase, so with it on, tf (published after the
// tick) would not show the poses the contacts were detected at.
#include "fcl_mesh.hpp"
#include "rostest_util.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/mesh_resource.hpp"
#include "sphere_tree_collision/scene/entity_request.hpp"

#include <gtest/gtest.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <tf2_msgs/TFMessage.h>

#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <set>

namespace {

using sphere_tree_collision::ContactArray;
using sphere_tree_collision::SpawnEntity;
using sphere_tree_collision::TickStats;
using stc::truth::FclMesh;

constexpr int kTicksToCheck = 60;
constexpr double kStartTimeout = 40.0;   // s: node start-up on a busy machine
constexpr double kSpawnTimeout = 15.0;   // s per entity
constexpr double kRecordTimeout = 120.0;  // s: a liveness bound; recording ends at kTicksToCheck matched ticks
// FCL's mesh distance is exact up to rounding; poses travel as doubles.
constexpr double kGapTolerance = 1e-6;

// ---------------------------------------------------------------------------
// The scene: a 3 x 3 x 2 lattice of presets spinning in place (neighbours'
// bounding spheres overlap), an explicit voxel grid (a cage) and a static
// plate below. Fixed seed: the same scene every run.

SpawnEntity preset(const std::string& name, std::uint32_t resolution, double voxel_size) {
  SpawnEntity m;
  m.preset = name;
  m.resolution = resolution;
  m.voxel_size = voxel_size;
  m.pose.orientation.w = 1.0;
  m.density = 1000.0;
  m.restitution = 0.3;
  m.friction = 0.5;
  return m;
}

std::vector<SpawnEntity> scenePlan() {
  std::mt19937 rng(20240605);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> spin(0.8, 2.0);
  const char* const kPresets[] = {"cube", "sphere", "rock", "rod", "plate", "L", "ring"};
  const std::uint32_t kResolutions[] = {8, 6, 10};
  const double kVoxelSizes[] = {0.05, 0.06, 0.04};  // ~0.4 m across each

  std::vector<SpawnEntity> plan;
  int k = 0;
  for (int iz = 0; iz < 2; ++iz) {
    for (int iy = 0; iy < 3; ++iy) {
      for (int ix = 0; ix < 3; ++ix, ++k) {
        SpawnEntity m = preset(kPresets[k % 7], kResolutions[k % 3], kVoxelSizes[k % 3]);
        m.seed = static_cast<std::uint32_t>(k + 1);
        m.pose.position.x = 0.38 * (ix - 1);
        m.pose.position.y = 0.38 * (iy - 1);
        m.pose.position.z = 0.5 + 0.38 * iz;
        stc::Quat q(unit(rng), unit(rng), unit(rng), unit(rng));
        q.normalize();
        m.pose.orientation = stc_ros::toQuaternionMsg(q);
        m.twist.linear = stc_ros::toVector3Msg(0.03 * stc::Vec3(unit(rng), unit(rng), unit(rng)));
        const stc::Vec3 axis = stc::Vec3(unit(rng), unit(rng), unit(rng)).normalized();
        m.twist.angular = stc_ros::toVector3Msg(spin(rng) * axis);
        plan.push_back(m);
      }
    }
  }
  // A cage: the 12 edges of a 5^3 grid (non-convex, explicit grid path).
  SpawnEntity cage;
  cage.dims = {5, 5, 5};
  cage.voxel_size = 0.07;
  for (int z = 0; z < 5; ++z) {
    for (int y = 0; y < 5; ++y) {
      for (int x = 0; x < 5; ++x) {
        const int on_border = (x == 0 || x == 4) + (y == 0 || y == 4) + (z == 0 || z == 4);
        cage.occupancy.push_back(on_border >= 2 ? 1 : 0);
      }
    }
  }
  cage.pose.position.x = 0.6;
  cage.pose.position.y = 0.05;
  cage.pose.position.z = 0.7;
  cage.pose.orientation.w = 1.0;
  cage.twist.angular.z = 1.2;
  cage.twist.angular.x = 0.5;
  cage.density = 500.0;
  cage.restitution = 0.2;
  cage.friction = 0.4;
  plan.push_back(cage);
  // A static plate the bottom row grazes.
  SpawnEntity floor = preset("plate", 12, 0.1);
  floor.pose.position.z = 0.22;
  floor.is_static = true;
  plan.push_back(floor);
  return plan;
}

// ---------------------------------------------------------------------------
// Ground truth of one entity, built by the node's own shape path.

struct Truth {
  const stc::ShapeInfo* shape = nullptr;
  std::shared_ptr<FclMesh> mesh;
  stc::Vec3 surface_point;  // a body-frame point on the surface (a mesh vertex)
  bool is_static = false;
};

class TruthShapes {
 public:
  // Adds the entity of `msg` to a local World exactly as the node does.
  Truth add(const SpawnEntity& msg) {
    const stc::EntityId local_id = stc::addRequest(world_, stc_ros::toEntityRequest(msg), {}, stc_ros::resolveMeshResource);
    const stc::ShapeId shape_id = world_.bodyShapes()[*world_.indexOf(local_id)];
    Truth t;
    t.shape = &world_.shape(shape_id);  // World keeps shapes in a deque: stable address
    auto& mesh = meshes_[shape_id];
    if (!mesh) mesh = stc::truth::makeFclMesh(t.shape->voxels, t.shape->body_origin);
    t.mesh = mesh;
    t.surface_point = stc::truth::buildSurfaceMesh(t.shape->voxels, t.shape->body_origin).vertices.front();
    t.is_static = msg.is_static;
    return t;
  }

 private:
  stc::World world_;
  std::map<stc::ShapeId, std::shared_ptr<FclMesh>> meshes_;
};

// The true gap between two solids: 0 when the surfaces cross or one holds the
// other (FCL's mesh test sees surfaces only), else FCL's surface distance.
double trueGap(const Truth& a, const stc::Pose& pa, const Truth& b, const stc::Pose& pb, bool surfaces_collide) {
  if (surfaces_collide) return 0.0;
  const stc::Vec3 a_in_b = pb.orientation.conjugate() * (pa.apply(a.surface_point) - pb.position);
  if (stc::truth::insideSolid(b.shape->voxels, b.shape->body_origin, a_in_b)) return 0.0;
  const stc::Vec3 b_in_a = pa.orientation.conjugate() * (pb.apply(b.surface_point) - pa.position);
  if (stc::truth::insideSolid(a.shape->voxels, a.shape->body_origin, b_in_a)) return 0.0;
  return stc::truth::exactDistance(*a.mesh, pa, *b.mesh, pb);
}

// ---------------------------------------------------------------------------
// One world node under test: spawn through its topic, record its output.

std::optional<stc::EntityId> idOfFrame(const std::string& frame) {
  const std::string prefix = "entity_";
  if (frame.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  return static_cast<stc::EntityId>(std::stoul(frame.substr(prefix.size())));
}

class WorldUnderTest {
 public:
  explicit WorldUnderTest(const std::string& ns) : ns_(ns) {
    ros::NodeHandle nh(ns);
    spawn_pub_ = nh.advertise<SpawnEntity>("collision_world/spawn", 100);
    contacts_sub_ = nh.subscribe<ContactArray>("collision_world/contacts", 1000, [this](const ContactArray::ConstPtr& m) {
      if (recording_) contacts_[m->header.stamp] = *m;
    });
    // The node's /tf is remapped into the namespace (two worlds, one tf tree each).
    tf_sub_ = nh.subscribe<tf2_msgs::TFMessage>("tf", 1000, [this](const tf2_msgs::TFMessage::ConstPtr& m) {
      if (m->transforms.empty()) return;
      for (const auto& t : m->transforms) {
        if (auto id = idOfFrame(t.child_frame_id)) frames_seen_.insert(*id);
      }
      if (recording_) tf_[m->transforms.front().header.stamp] = *m;
    });
    // Static entities are on tf_static (latched, sent whole when they change), not in each tick's tf.
    tf_static_sub_ = nh.subscribe<tf2_msgs::TFMessage>("tf_static", 10, [this](const tf2_msgs::TFMessage::ConstPtr& m) {
      static_poses_.clear();
      for (const auto& t : m->transforms) {
        const auto id = idOfFrame(t.child_frame_id);
        if (!id) continue;
        frames_seen_.insert(*id);
        static_poses_[*id] = stc::Pose{stc_ros::toEigen(t.transform.translation), stc_ros::toEigen(t.transform.rotation)};
      }
    });
    stats_sub_ = nh.subscribe<TickStats>("collision_world/tick_stats", 1000, [this](const TickStats::ConstPtr& m) {
      if (!recording_) return;
      ++stats_ticks_;
      sphere_tests_ += m->sphere_tests;
    });
  }

  const std::string& ns() const { return ns_; }
  bool connected() const {
    return spawn_pub_.getNumSubscribers() > 0 && contacts_sub_.getNumPublishers() > 0 && tf_sub_.getNumPublishers() > 0;
  }
  std::size_t framesSeen() const { return frames_seen_.size(); }

  // Publishes `msg`; the caller waits until a new frame shows up.
  void spawn(const SpawnEntity& msg) {
    frames_before_ = frames_seen_;
    spawn_pub_.publish(msg);
  }
  // The id of the entity spawned last, once its frame is in tf.
  std::optional<stc::EntityId> newId() const {
    for (stc::EntityId id : frames_seen_) {
      if (frames_before_.count(id) == 0) return id;
    }
    return std::nullopt;
  }

  void startRecording() {
    contacts_.clear();
    tf_.clear();
    stats_ticks_ = 0;
    sphere_tests_ = 0;
    recording_ = true;
  }
  double meanSphereTests() const { return stats_ticks_ == 0 ? 0.0 : double(sphere_tests_) / stats_ticks_; }
  void stopRecording() { recording_ = false; }
  // Ticks whose contacts and tf were both received (same stamp).
  std::size_t matchedTicks() const {
    std::size_t n = 0;
    for (const auto& [stamp, msg] : contacts_) n += tf_.count(stamp);
    return n;
  }
  std::size_t contactTicks() const { return contacts_.size(); }
  const std::map<ros::Time, ContactArray>& contacts() const { return contacts_; }
  const std::map<ros::Time, tf2_msgs::TFMessage>& tf() const { return tf_; }
  const std::map<stc::EntityId, stc::Pose>& staticPoses() const { return static_poses_; }

 private:
  std::string ns_;
  ros::Publisher spawn_pub_;
  ros::Subscriber contacts_sub_, tf_sub_, tf_static_sub_, stats_sub_;
  std::size_t stats_ticks_ = 0;
  std::int64_t sphere_tests_ = 0;
  std::set<stc::EntityId> frames_seen_, frames_before_;
  bool recording_ = false;
  std::map<ros::Time, ContactArray> contacts_;
  std::map<ros::Time, tf2_msgs::TFMessage> tf_;
  std::map<stc::EntityId, stc::Pose> static_poses_;  // from the last tf_static
};

// ---------------------------------------------------------------------------
// The recorded session, shared by the tests: both worlds, spawned and recorded once.

struct Session {
  std::unique_ptr<WorldUnderTest> unlimited, tight;
  // Per world: entity id -> truth (the plan index decides the shape).
  std::map<stc::EntityId, Truth> truth_unlimited, truth_tight;
  TruthShapes shapes;  // owns what the Truths point at
  std::string error;  // set when the session could not be recorded
};

Session& session() {
  static Session s;
  static bool done = false;
  if (done) return s;
  done = true;
  s.unlimited = std::make_unique<WorldUnderTest>("unlimited");
  s.tight = std::make_unique<WorldUnderTest>("tight");
  WorldUnderTest* worlds[2] = {s.unlimited.get(), s.tight.get()};
  std::map<stc::EntityId, Truth>* truths[2] = {&s.truth_unlimited, &s.truth_tight};

  if (!stc_test::spinUntil([&] { return worlds[0]->connected() && worlds[1]->connected(); }, kStartTimeout)) {
    s.error = "world nodes not connected (spawn, contacts, tf) within " + std::to_string(kStartTimeout) + " s";
    return s;
  }
  for (const SpawnEntity& msg : scenePlan()) {
    const Truth truth = s.shapes.add(msg);
    for (int w = 0; w < 2; ++w) worlds[w]->spawn(msg);
    for (int w = 0; w < 2; ++w) {
      if (!stc_test::spinUntil([&] { return worlds[w]->newId().has_value(); }, kSpawnTimeout)) {
        s.error = worlds[w]->ns() + ": no new tf frame within " + std::to_string(kSpawnTimeout) + " s of a spawn";
        return s;
      }
      (*truths[w])[*worlds[w]->newId()] = truth;
    }
  }
  for (WorldUnderTest* w : worlds) w->startRecording();
  stc_test::spinUntil([&] { return worlds[0]->matchedTicks() >= kTicksToCheck && worlds[1]->matchedTicks() >= kTicksToCheck; },
                      kRecordTimeout);
  for (WorldUnderTest* w : worlds) w->stopRecording();
  return s;
}

// ---------------------------------------------------------------------------
// The check of one world's recording against FCL.

// Contact pairs (one per entity pair and tick) of one kind: resolved at the
// leaves, or accepted unresolved.
struct PairTally {
  std::size_t pairs = 0;
  std::size_t false_positives = 0;  // FCL: the solids are apart
  double false_gap_sum = 0.0;       // FCL gaps of the false positives
  double bound_sum = 0.0;
  double level_sum = 0.0;
  double worst_gap_over_bound = 0.0;

  void add(double gap, double bound, int level) {
    ++pairs;
    bound_sum += bound;
    level_sum += level;
    if (gap > 0.0) {
      ++false_positives;
      false_gap_sum += gap;
      if (bound > 0.0) worst_gap_over_bound = std::max(worst_gap_over_bound, gap / bound);
    }
  }
};

struct Tally {
  std::size_t ticks = 0, ticks_without_tf = 0;
  std::size_t fcl_colliding = 0, missed = 0;
  std::size_t bound_violations = 0;
  std::size_t contacts = 0;
  PairTally resolved, unresolved;
};

struct PairContact {
  double gap_bound = std::numeric_limits<double>::infinity();
  bool resolved = true;
  int level = 0;
};

Tally check(const WorldUnderTest& world, const std::map<stc::EntityId, Truth>& truth, bool expect_all_resolved) {
  Tally t;
  int reports = 0;  // failure messages, capped so one systematic error stays readable
  for (const auto& [stamp, contacts] : world.contacts()) {
    const auto tf_it = world.tf().find(stamp);
    if (tf_it == world.tf().end()) {
      ++t.ticks_without_tf;  // the tf message of that tick was not received
      continue;
    }
    ++t.ticks;
    std::map<stc::EntityId, stc::Pose> poses;
    for (const auto& tr : tf_it->second.transforms) {
      const auto id = idOfFrame(tr.child_frame_id);
      if (!id) continue;
      stc::Pose p;
      p.position = stc_ros::toEigen(tr.transform.translation);
      p.orientation = stc_ros::toEigen(tr.transform.rotation);
      poses[*id] = p;
    }
    poses.insert(world.staticPoses().begin(), world.staticPoses().end());
    EXPECT_EQ(poses.size(), truth.size()) << world.ns() << ": tf of tick " << stamp << " lacks entities";

    std::map<std::pair<stc::EntityId, stc::EntityId>, PairContact> pairs;
    for (const auto& c : contacts.contacts) {
      ++t.contacts;
      auto& p = pairs[{std::min(c.entity_a, c.entity_b), std::max(c.entity_a, c.entity_b)}];
      p.gap_bound = std::min(p.gap_bound, c.gap_bound);
      p.resolved = p.resolved && c.resolved;
      p.level = std::max(p.level, static_cast<int>(c.level));
      if (expect_all_resolved && !c.resolved && reports++ < 10) {
        ADD_FAILURE() << world.ns() << ": unresolved contact " << c.entity_a << "-" << c.entity_b
                      << " without a budget";
      }
    }

    for (auto a = truth.begin(); a != truth.end(); ++a) {
      for (auto b = std::next(a); b != truth.end(); ++b) {
        if (!poses.count(a->first) || !poses.count(b->first)) continue;
        const stc::Pose& pa = poses[a->first];
        const stc::Pose& pb = poses[b->first];
        const auto found = pairs.find({a->first, b->first});
        const double reach = a->second.shape->bounding_radius + b->second.shape->bounding_radius;
        if (found == pairs.end() && (pa.position - pb.position).norm() > reach) continue;  // cannot touch
        const bool colliding = stc::truth::exactCollide(*a->second.mesh, pa, *b->second.mesh, pb);
        // Two static entities are never tested (nothing can change between them).
        if (colliding && !(a->second.is_static && b->second.is_static)) {
          ++t.fcl_colliding;
          if (found == pairs.end()) {
            ++t.missed;
            if (reports++ < 10) {
              ADD_FAILURE() << world.ns() << ": FCL finds " << a->first << "-" << b->first
                            << " colliding at tick " << stamp << " but there is no contact";
            }
          }
        }
        if (found == pairs.end()) continue;
        const PairContact& pc = found->second;
        const double gap = trueGap(a->second, pa, b->second, pb, colliding);
        if (pc.gap_bound < gap - kGapTolerance) {
          ++t.bound_violations;
          if (reports++ < 10) {
            ADD_FAILURE() << world.ns() << ": contact " << a->first << "-" << b->first << " at tick " << stamp
                          << " (level " << pc.level << (pc.resolved ? ", resolved" : ", unresolved")
                          << "): gap_bound " << pc.gap_bound << " < FCL gap " << gap;
          }
        }
        (pc.resolved ? t.resolved : t.unresolved).add(gap, pc.gap_bound, pc.level);
      }
    }
  }
  return t;
}

double ratio(double a, std::size_t b) { return b == 0 ? 0.0 : a / static_cast<double>(b); }

void print(const WorldUnderTest& world, const Tally& t) {
  const char* name = world.ns().c_str();
  std::printf("[accuracy] %s: %zu ticks checked (%zu without their tf), %.0f sphere tests per tick, %zu contacts\n",
              name, t.ticks, t.ticks_without_tf, world.meanSphereTests(), t.contacts);
  std::printf("[accuracy] %s: FCL-colliding pairs %zu, missed %zu; gap bound violations %zu\n", name,
              t.fcl_colliding, t.missed, t.bound_violations);
  const PairTally* kinds[2] = {&t.resolved, &t.unresolved};
  const char* kind_names[2] = {"resolved at the leaves", "accepted unresolved"};
  for (int k = 0; k < 2; ++k) {
    const PairTally& p = *kinds[k];
    if (p.pairs == 0) continue;
    std::printf("[accuracy] %s: %s: %zu contact pairs, mean level %.2f, false positives %zu (%.1f%%), "
                "mean true gap of those %.2f mm, mean gap bound %.2f mm, worst true gap / bound %.3f\n",
                name, kind_names[k], p.pairs, ratio(p.level_sum, p.pairs), p.false_positives,
                100.0 * ratio(p.false_positives, p.pairs), 1e3 * ratio(p.false_gap_sum, p.false_positives),
                1e3 * ratio(p.bound_sum, p.pairs), p.worst_gap_over_bound);
  }
  std::fflush(stdout);
}

TEST(Accuracy, UnlimitedBudgetMissesNoCollision) {
  Session& s = session();
  ASSERT_TRUE(s.error.empty()) << s.error;
  ASSERT_GE(s.unlimited->matchedTicks(), static_cast<std::size_t>(kTicksToCheck / 2))
      << "too few ticks with contacts and tf (" << s.unlimited->contactTicks() << " contact messages)";
  const Tally t = check(*s.unlimited, s.truth_unlimited, /*expect_all_resolved=*/true);
  print(*s.unlimited, t);
  EXPECT_EQ(t.missed, 0u);
  EXPECT_EQ(t.bound_violations, 0u);
  EXPECT_EQ(t.unresolved.pairs, 0u) << "without a budget every pair is resolved at the leaves";
  // The scene must exercise the check: many colliding pairs over the run.
  EXPECT_GE(t.fcl_colliding, t.ticks) << "the scene has too few collisions to test anything";
}

TEST(Accuracy, TightBudgetGapBoundsHold) {
  Session& s = session();
  ASSERT_TRUE(s.error.empty()) << s.error;
  ASSERT_GE(s.tight->matchedTicks(), static_cast<std::size_t>(kTicksToCheck / 2))
      << "too few ticks with contacts and tf (" << s.tight->contactTicks() << " contact messages)";
  const Tally t = check(*s.tight, s.truth_tight, /*expect_all_resolved=*/false);
  print(*s.tight, t);
  EXPECT_EQ(t.bound_violations, 0u);
  EXPECT_EQ(t.missed, 0u) << "policy accept: an interrupted pair becomes a contact, so none is missed";
  EXPECT_GT(t.unresolved.pairs, 0u) << "the budget left nothing unresolved: it tests nothing";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "accuracy_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
