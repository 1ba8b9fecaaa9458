// Fracture (issue 14, item 3): split geometry, pieces placed where their
// voxels were, momentum and energy through a break, strength 0 never breaks,
// small pieces attached or dropped, breaks deferred past the deadline, bad
// input rejected naming the field.
#include "deadline.hpp"
#include "dynamics.hpp"
#include "fracture.hpp"
#include "physics.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include "world_refuses.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace stc {
namespace {

constexpr double kVoxel = 0.05;
constexpr double kDt = 1.0 / 240.0;

VoxelShape solidBox(int nx, int ny, int nz, double voxel = kVoxel) {
  return VoxelShape::create(nx, ny, nz, voxel, std::vector<std::uint8_t>(static_cast<std::size_t>(nx) * ny * nz, 1));
}

// A flat L (6 x 6 x 1): a bar along x (j < 2) and a bar along y (i < 2), 20 voxels.
VoxelShape flatL() {
  std::vector<std::uint8_t> cells(36, 0);
  for (int j = 0; j < 6; ++j) {
    for (int i = 0; i < 6; ++i) cells[i + 6 * j] = (i < 2 || j < 2) ? 1 : 0;
  }
  return VoxelShape::create(6, 6, 1, kVoxel, cells);
}

// Parent voxel (as grid indices) of every occupied voxel of the pieces.
std::vector<std::array<int, 3>> pieceVoxels(const std::vector<VoxelPiece>& pieces) {
  std::vector<std::array<int, 3>> out;
  for (const VoxelPiece& p : pieces) {
    for (int k = 0; k < p.shape.nz(); ++k)
      for (int j = 0; j < p.shape.ny(); ++j)
        for (int i = 0; i < p.shape.nx(); ++i)
          if (p.shape.occupied(i, j, k)) out.push_back({i + p.offset.x(), j + p.offset.y(), k + p.offset.z()});
  }
  return out;
}

std::vector<std::array<int, 3>> voxelsOf(const VoxelShape& s) {
  std::vector<std::array<int, 3>> out;
  for (int k = 0; k < s.nz(); ++k)
    for (int j = 0; j < s.ny(); ++j)
      for (int i = 0; i < s.nx(); ++i)
        if (s.occupied(i, j, k)) out.push_back({i, j, k});
  std::sort(out.begin(), out.end());
  return out;
}

FractureOptions keepAll() {
  FractureOptions o;
  o.min_piece_voxels = 1;
  return o;
}

TEST(FractureGeometry, PlaneThroughACubeGivesTwoHalvesThatPartitionIt) {
  const VoxelShape cube = solidBox(6, 6, 6);
  // Plane x = 3 voxels: centres at 2.5 and 3.5 voxels fall on either side.
  const SplitPlane plane{Vec3(3.0 * kVoxel, 0.1, 0.2), Vec3::UnitX()};
  const std::vector<VoxelPiece> pieces = splitVoxelShape(cube, plane, keepAll());
  ASSERT_EQ(pieces.size(), 2u);
  for (const VoxelPiece& p : pieces) {
    EXPECT_EQ(p.voxels, 108);
    EXPECT_EQ(p.shape.nx(), 3);
    EXPECT_EQ(p.shape.ny(), 6);
    EXPECT_EQ(p.shape.nz(), 6);
  }
  std::vector<std::array<int, 3>> got = pieceVoxels(pieces);
  std::vector<std::array<int, 3>> all = voxelsOf(cube);
  std::sort(got.begin(), got.end());
  EXPECT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end()) << "a voxel is in two pieces";
  EXPECT_EQ(got, all) << "the pieces' union is not the parent";
}

TEST(FractureGeometry, DiagonalPlaneCutsAnLIntoThreeComponents) {
  const VoxelShape l = flatL();
  // i + j >= 4 on the + side: the two bar ends (5 voxels each) apart, the corner (10) between.
  const SplitPlane plane{Vec3(2.5, 2.5, 0.0) * kVoxel, Vec3(1.0, 1.0, 0.0).normalized()};
  int count = 0;
  labelSplitComponents(l, plane, &count);
  EXPECT_EQ(count, 3);
  const std::vector<VoxelPiece> pieces = splitVoxelShape(l, plane, keepAll());
  ASSERT_EQ(pieces.size(), 3u);
  EXPECT_EQ(pieces[0].voxels, 10);  // largest first
  EXPECT_EQ(pieces[1].voxels, 5);
  EXPECT_EQ(pieces[2].voxels, 5);
  std::vector<std::array<int, 3>> got = pieceVoxels(pieces);
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, voxelsOf(l));
}

TEST(FractureGeometry, SmallPiecesAttachToTheLargestOrVanish) {
  const VoxelShape l = flatL();
  const SplitPlane plane{Vec3(2.5, 2.5, 0.0) * kVoxel, Vec3(1.0, 1.0, 0.0).normalized()};
  FractureOptions options;
  options.min_piece_voxels = 6;
  options.small_pieces = SmallPieces::Attach;
  std::vector<VoxelPiece> pieces = splitVoxelShape(l, plane, options);
  ASSERT_EQ(pieces.size(), 1u);  // both ends went back to the corner: nothing split
  EXPECT_EQ(pieces[0].voxels, 20);

  options.small_pieces = SmallPieces::Vanish;
  pieces = splitVoxelShape(l, plane, options);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].voxels, 10);  // the ends are dust

  // A thin slice off a cube: attached, the cube stays whole; vanished, 5/6 are left.
  const VoxelShape cube = solidBox(6, 6, 6);
  const SplitPlane slice{Vec3(5.0 * kVoxel, 0.0, 0.0), Vec3::UnitX()};
  options.min_piece_voxels = 40;
  options.small_pieces = SmallPieces::Attach;
  EXPECT_EQ(splitVoxelShape(cube, slice, options).at(0).voxels, 216);
  options.small_pieces = SmallPieces::Vanish;
  pieces = splitVoxelShape(cube, slice, options);
  ASSERT_EQ(pieces.size(), 1u);
  EXPECT_EQ(pieces[0].voxels, 180);
  EXPECT_EQ(pieces[0].offset, Eigen::Vector3i::Zero());
}

TEST(FractureGeometry, PlaneHoldsTheNormalAndPassesThroughTheCentre) {
  const Vec3 p(0.3, -0.1, 0.0), n = Vec3(0.0, 0.0, 1.0), c(0.0, 0.2, 0.5);
  const SplitPlane plane = fracturePlane(p, n, c);
  EXPECT_NEAR(plane.normal.norm(), 1.0, 1e-12);
  EXPECT_NEAR(plane.normal.dot(n), 0.0, 1e-12);
  EXPECT_NEAR(plane.normal.dot(c - plane.point), 0.0, 1e-12);
  // Head-on: still a plane holding the normal.
  const SplitPlane head_on = fracturePlane(Vec3::Zero(), n, Vec3(0.0, 0.0, 1.0));
  EXPECT_NEAR(head_on.normal.dot(n), 0.0, 1e-12);
  EXPECT_NEAR(head_on.normal.norm(), 1.0, 1e-12);
}

TEST(FractureGeometry, BadOptionsAreRejectedNamingTheField) {
  try {
    parseSmallPieces("dust");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "fracture.small_pieces");
  }
  WorldConfig config;
  config.fracture.min_piece_voxels = 0;
  EXPECT_TRUE(worldRefuses(config, "fracture.min_piece_voxels"));
}

// ---------------------------------------------------------------------------------
// In a World

EntitySpec spec(ShapeId shape, const Vec3& position, const std::string& name, double strength) {
  EntitySpec s;
  s.shape = shape;
  s.name = name;
  s.pose.position = position;
  s.pose.orientation = Quat(Eigen::AngleAxisd(0.4, Vec3(1.0, 2.0, 0.5).normalized()));
  s.density = 2600.0;
  s.material = Material{0.3, 0.6, strength};
  return s;
}

ShapeId rockShape(World& w) {
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = kVoxel;
  p.seed = 3;
  return w.addShape("rock", makePreset("rock", p));
}

// World centres of every voxel of a body, sorted (to compare as sets).
std::vector<std::array<double, 3>> worldVoxelCentres(const World& w, std::size_t index) {
  const ShapeInfo& info = w.shape(w.bodyShapes()[index]);
  const Pose& pose = w.bodies()[index].pose;
  std::vector<std::array<double, 3>> out;
  for (const auto& v : voxelsOf(info.voxels)) {
    const Vec3 c = pose.apply((Vec3(v[0], v[1], v[2]) + Vec3::Constant(0.5)) * info.voxels.voxelSize() - info.body_origin);
    out.push_back({c.x(), c.y(), c.z()});
  }
  return out;
}

// A World's parts call back the World that holds them (fracture adds and
// removes bodies through its public calls): after a move, the World moved into.
TEST(FractureWorld, AMovedWorldBreaksItsBodiesThroughItsOwnCalls) {
  World first;
  const EntityId id = first.addEntity(spec(rockShape(first), Vec3::Zero(), "rock", 5.0));
  World moved(std::move(first));
  World assigned;
  assigned = std::move(moved);
  const Vec3 impact = assigned.bodies()[0].pose.position + Vec3(0.05, 0.02, -0.15);
  const std::vector<EntityId> pieces = assigned.breakEntity(id, impact, Vec3::UnitZ());
  ASSERT_GE(pieces.size(), 2u);
  EXPECT_FALSE(assigned.indexOf(id).has_value());
  EXPECT_EQ(assigned.entityCount(), pieces.size());
}

TEST(FractureWorld, BreakKeepsMomentumEnergyAndEveryVoxelInPlace) {
  World w;
  const ShapeId rock = rockShape(w);
  EntitySpec s = spec(rock, Vec3(1.0, -2.0, 3.0), "rock", 5.0);
  s.linear_velocity = Vec3(3.0, -1.0, 2.0);
  s.angular_velocity = Vec3(4.0, -2.0, 7.0);
  const EntityId id = w.addEntity(s);
  const std::vector<std::array<double, 3>> before_voxels = worldVoxelCentres(w, 0);
  const Vec3 p0 = linearMomentum(w.bodies());
  const Vec3 l0 = angularMomentum(w.bodies());
  const double e0 = totalEnergy(w.bodies(), Vec3::Zero());

  const Vec3 impact = w.bodies()[0].pose.position + Vec3(0.05, 0.02, -0.15);
  const std::vector<EntityId> pieces = w.breakEntity(id, impact, Vec3::UnitZ());
  ASSERT_GE(pieces.size(), 2u);
  EXPECT_FALSE(w.indexOf(id).has_value());
  EXPECT_EQ(w.entityCount(), pieces.size());
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    EXPECT_EQ(w.findByName("rock/piece" + std::to_string(k)), pieces[k]);
  }
  EXPECT_LE((linearMomentum(w.bodies()) - p0).norm(), 1e-9 * p0.norm());
  EXPECT_LE((angularMomentum(w.bodies()) - l0).norm(), 1e-9 * l0.norm());
  EXPECT_NEAR(totalEnergy(w.bodies(), Vec3::Zero()), e0, 1e-9 * e0);

  // The pieces' voxels are the parent's, where they were: disjoint, and all of them.
  std::vector<std::array<double, 3>> after_voxels;
  for (std::size_t i = 0; i < w.entityCount(); ++i) {
    const auto c = worldVoxelCentres(w, i);
    after_voxels.insert(after_voxels.end(), c.begin(), c.end());
  }
  ASSERT_EQ(after_voxels.size(), before_voxels.size());
  std::vector<bool> used(before_voxels.size(), false);
  for (const auto& a : after_voxels) {
    std::size_t match = before_voxels.size();
    for (std::size_t b = 0; b < before_voxels.size(); ++b) {
      const double d = std::hypot(a[0] - before_voxels[b][0], a[1] - before_voxels[b][1], a[2] - before_voxels[b][2]);
      if (d < 1e-9) match = b;
    }
    ASSERT_LT(match, before_voxels.size()) << "a piece's voxel is not where a parent voxel was";
    EXPECT_FALSE(used[match]) << "two pieces hold one voxel";
    used[match] = true;
  }
}

TEST(FractureWorld, SiblingsTouchButDoNotPenetrateAtBirth) {
  World w;
  const ShapeId rock = rockShape(w);
  EntitySpec s = spec(rock, Vec3::Zero(), "rock", 5.0);
  s.linear_velocity = Vec3(1.0, 0.5, 0.0);
  s.angular_velocity = Vec3(0.0, 0.0, 2.0);
  const EntityId id = w.addEntity(s);
  ASSERT_GE(w.breakEntity(id, Vec3(0.0, 0.0, -0.2), Vec3::UnitZ()).size(), 2u);
  const double e0 = totalEnergy(w.bodies(), Vec3::Zero());
  const TickReport r = w.step(kDt, Budget::unlimited());
  // Siblings share the cut's faces: the narrow phase finds them in contact,
  // but the voxel surfaces meet with no penetration beyond rounding, and
  // moving as one rigid body they do not push each other.
  EXPECT_GT(r.response.contacts, 0u);
  for (const Contact& c : w.contacts()) EXPECT_GE(c.separation, -1e-9);
  EXPECT_LE(physicsReport(w).solve.max_penetration, 1e-9);
  EXPECT_LE(totalEnergy(w.bodies(), Vec3::Zero()), e0 * (1.0 + 1e-9));
}

// A rock dropped fast onto a static slab; `strength` decides whether it breaks.
World dropScene(double strength, SmallPieces small = SmallPieces::Attach, int min_piece = 8) {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  config.fracture.small_pieces = small;
  config.fracture.min_piece_voxels = min_piece;
  World w(config);
  EntitySpec floor;
  floor.shape = w.addShape("slab", solidBox(40, 40, 2, 0.1));
  floor.pose.position = Vec3(0.0, 0.0, -0.1);
  floor.is_static = true;
  floor.material = Material{0.3, 0.6, 1.0};  // static: a strength is ignored
  w.addEntity(floor);
  EntitySpec rock = spec(rockShape(w), Vec3(0.0, 0.0, 0.5), "rock", strength);
  rock.linear_velocity = Vec3(1.0, 0.0, -12.0);
  rock.angular_velocity = Vec3(0.0, 3.0, 0.0);
  w.addEntity(rock);
  return w;
}

// Ticks until one breaks a body (the tick's index), or -1 within `ticks`.
int stepUntilBreak(World& w, int ticks) {
  for (int i = 0; i < ticks; ++i) {
    if (w.step(kDt, Budget::unlimited()).fracture.fractures > 0) return i;
  }
  return -1;
}

TEST(FractureWorld, StrengthZeroNeverBreaks) {
  World w = dropScene(0.0);
  for (int i = 0; i < 240; ++i) EXPECT_EQ(w.step(kDt, Budget::unlimited()).fracture.fractures, 0u);
  EXPECT_EQ(w.entityCount(), 2u);
  EXPECT_TRUE(w.findByName("rock").has_value());
}

TEST(FractureWorld, HardDropBreaksTheRockAndKeepsMomentumAndEnergyOfTheBreakTick) {
  World breaking = dropScene(1.0);
  World whole = dropScene(0.0);  // the same world, unbreakable: its state is the one just before the break
  const int tick = stepUntilBreak(breaking, 120);
  ASSERT_GE(tick, 0) << "the rock never broke";
  for (int i = 0; i <= tick; ++i) whole.step(kDt, Budget::unlimited());
  ASSERT_EQ(whole.entityCount(), 2u);

  EXPECT_FALSE(breaking.findByName("rock").has_value());
  EXPECT_GE(breaking.entityCount(), 3u);  // the slab and two pieces at least
  EXPECT_TRUE(breaking.findByName("rock/piece0").has_value());
  EXPECT_TRUE(breaking.findByName("rock/piece1").has_value());

  const Vec3 g(0.0, 0.0, -9.81);
  const Vec3 p0 = linearMomentum(whole.bodies()), p1 = linearMomentum(breaking.bodies());
  const Vec3 l0 = angularMomentum(whole.bodies()), l1 = angularMomentum(breaking.bodies());
  EXPECT_LE((p1 - p0).norm(), 1e-9 * p0.norm());
  EXPECT_LE((l1 - l0).norm(), 1e-9 * l0.norm());
  const double e0 = totalEnergy(whole.bodies(), g, kDt), e1 = totalEnergy(breaking.bodies(), g, kDt);
  EXPECT_LE(e1, e0 + 1e-9 * std::abs(e0));

  // Afterwards the pieces bounce and settle: energy falls, but for position
  // correction, which lifts a piece out of what it sank into (the shock
  // sweep lifts the upper piece alone: up to 4e-4 of it in a tick). The
  // bound is test_stability's: a gain under 1e-3 of the energy scale.
  double e = e1;
  for (int i = 0; i < 120; ++i) {
    breaking.step(kDt, Budget::unlimited());
    const double next = totalEnergy(breaking.bodies(), g, kDt);
    EXPECT_LE(next, e + 1e-3 * std::abs(e0)) << "tick " << i;
    e = next;
  }
  EXPECT_LT(e, e1);
}

TEST(FractureWorld, VanishedPiecesTakeTheirMassAway) {
  // A huge minimum piece: only the largest piece is left, lighter than the rock.
  World w = dropScene(1.0, SmallPieces::Vanish, 100000);
  const double mass0 = 1.0 / w.bodies()[1].inv_mass;
  ASSERT_GE(stepUntilBreak(w, 120), 0);
  ASSERT_EQ(w.entityCount(), 2u);
  const std::size_t piece = *w.indexOf(*w.findByName("rock/piece0"));
  EXPECT_LT(1.0 / w.bodies()[piece].inv_mass, mass0);

  World attached = dropScene(1.0, SmallPieces::Attach, 100000);
  for (int i = 0; i < 120; ++i) EXPECT_EQ(attached.step(kDt, Budget::unlimited()).fracture.fractures, 0u);
  EXPECT_TRUE(attached.findByName("rock").has_value());  // all pieces went back: it stayed whole
}

TEST(FractureWorld, BreaksAfterTheDeadlineWaitForTheNextTick) {
  World w = dropScene(1.0);
  double now = 0.0;
  w.setClock([&now] { return now += 1e-3; });  // every read a millisecond later
  // A tick budget the fixed phases alone overrun: every break is deferred.
  int deferred_tick = -1;
  for (int i = 0; i < 120 && deferred_tick < 0; ++i) {
    const TickReport r = w.step(kDt, Budget::ofTickSeconds(1e-4));
    if (r.fracture.fractures_deferred > 0) {
      EXPECT_EQ(r.fracture.fractures, 0u);
      EXPECT_TRUE(w.findByName("rock").has_value());
      deferred_tick = i;
    }
  }
  ASSERT_GE(deferred_tick, 0) << "nothing broke";
  // Each next tick builds one of the pieces' trees at its start (the queue
  // always moves, whatever the budget); the tick that has them all breaks it.
  TickReport next;
  int ticks = 0;
  do {
    next = w.step(kDt, Budget::ofTickSeconds(1e-4));
    ++ticks;
    EXPECT_EQ(next.fracture.piece_trees, 1u) << "tick " << ticks;
    EXPECT_GT(next.fracture.fracture_s, 0.0);
  } while (next.fracture.fractures == 0 && ticks < 10);
  EXPECT_EQ(next.fracture.fractures, 1u);
  EXPECT_EQ(next.fracture.fractures_deferred, 0u);
  EXPECT_FALSE(w.findByName("rock").has_value());
  ASSERT_TRUE(w.findByName("rock/piece0").has_value());
  ASSERT_EQ(w.broken().size(), 1u);
  std::vector<ShapeId> shapes;
  for (const EntityId piece : w.broken()[0].pieces) shapes.push_back(w.bodyShapes()[*w.indexOf(piece)]);
  std::sort(shapes.begin(), shapes.end());
  EXPECT_EQ(ticks, std::unique(shapes.begin(), shapes.end()) - shapes.begin()) << "one tick per new tree";
}

// A clock on which time passes only while shapes are added: every voxel of a
// shape added after it was made costs `per_voxel` seconds. The pieces' trees
// are then the whole cost of a tick, and deterministic.
class TreeWorkClock {
 public:
  TreeWorkClock(const World& w, double per_voxel) : w_(&w), first_(w.shapeCount()), per_voxel_(per_voxel) {}
  double operator()() const {
    double t = 0.0;
    for (ShapeId s = first_; s < w_->shapeCount(); ++s) t += per_voxel_ * w_->shape(s).voxels.occupiedCount();
    return t;
  }

 private:
  const World* w_;
  ShapeId first_;
  double per_voxel_;
};

// How far a body of `shape` turned by `q` reaches from its centre of mass along `dir`.
double reach(const World& w, ShapeId shape, const Quat& q, const Vec3& dir) {
  const ShapeInfo& info = w.shape(shape);
  const double s = info.voxels.voxelSize();
  double most = -std::numeric_limits<double>::infinity();
  for (const auto& v : voxelsOf(info.voxels)) {
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 p = Vec3(v[0] + (corner & 1), v[1] + ((corner >> 1) & 1), v[2] + ((corner >> 2) & 1)) * s;
      most = std::max(most, (q * (p - info.body_origin)).dot(dir));
    }
  }
  return most;
}

TEST(FractureWorld, PieceTreesKeepTheTickDeadlineAndEveryBreakIsMadeWithMomentumKept) {
  // No gravity, nothing static: four breakable rocks, each turned its own
  // way (their pieces differ), hit a free 1 m block in the same tick; every
  // impulse is internal, so the world's linear momentum is constant, breaks
  // included.
  World w;
  EntitySpec block;
  block.shape = w.addShape("block", solidBox(10, 10, 10, 0.1));
  block.density = 1000.0;
  w.addEntity(block);
  const ShapeId rock = rockShape(w);
  const std::int64_t rock_voxels = w.shape(rock).voxels.occupiedCount();
  const std::array<Vec3, 4> towards = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY()};
  for (int k = 0; k < 4; ++k) {
    EntitySpec s = spec(rock, Vec3::Zero(), "rock" + std::to_string(k), 1.0);
    s.pose.orientation = Quat(Eigen::AngleAxisd(0.4 + 0.7 * k, Vec3(1.0, 2.0 - k, 0.5 + k).normalized()));
    // 0.1 m from the block's face: all four touch it in the same tick.
    s.pose.position = -towards[k] * (0.5 + 0.1 + reach(w, rock, s.pose.orientation, towards[k]));
    s.linear_velocity = 12.0 * towards[k];
    s.angular_velocity = Vec3(0.5, 2.0, -1.0) * (k + 1);
    w.addEntity(s);
  }
  // A whole rock's trees cost 40 % of the tick: four rocks' do not fit in one.
  const double budget = 0.01;
  w.setClock(TreeWorkClock(w, 0.4 * budget / static_cast<double>(rock_voxels)));
  const Vec3 p0 = linearMomentum(w.bodies());
  double scale = 0.0;
  for (const BodyState& b : w.bodies()) scale += b.linear_velocity.norm() / b.inv_mass;

  std::size_t breaks = 0, trees = 0, most_deferred = 0, trees_of_one_tick = 0;
  TickReport r;
  for (int i = 0; i < 120; ++i) {
    r = w.step(kDt, Budget::ofTickSeconds(budget));
    // Stamps of the World's clock: the tick ends by its deadline.
    EXPECT_LE(r.phases.total_s, budget * (1.0 + 1e-12)) << "tick " << i << ": " << r.fracture.piece_trees << " trees";
    EXPECT_LE((linearMomentum(w.bodies()) - p0).norm(), 1e-9 * scale) << "tick " << i;
    breaks += r.fracture.fractures;
    trees += r.fracture.piece_trees;
    most_deferred = std::max(most_deferred, r.fracture.fractures_deferred);
    trees_of_one_tick = std::max(trees_of_one_tick, r.fracture.piece_trees);
  }
  EXPECT_GE(breaks, 3u);
  EXPECT_GE(most_deferred, 1u) << "every break fitted: the test does not load the budget";
  EXPECT_LT(trees_of_one_tick, trees) << "the trees were not spread over ticks";
  EXPECT_EQ(r.fracture.fractures_deferred, 0u) << "a deferred break was never made";
  for (const char* name : {"rock0", "rock1", "rock2", "rock3"}) EXPECT_FALSE(w.findByName(name).has_value()) << name;
}

TEST(FractureWorld, PiecesAreWeakerAsTheirVolumeToTheExponent) {
  EXPECT_DOUBLE_EQ(pieceStrength(8.0, 1, 8, 1.0 / 3.0), 4.0);
  EXPECT_DOUBLE_EQ(pieceStrength(8.0, 1, 8, 0.0), 8.0);
  World w;
  const ShapeId cube = w.addShape("cube6", solidBox(6, 6, 6));
  const EntityId a = w.addEntity(spec(cube, Vec3::Zero(), "a", 10.0));
  const std::vector<EntityId> pieces = w.breakEntity(a, Vec3(0.0, 0.0, -0.15), Vec3::UnitY());
  ASSERT_GE(pieces.size(), 2u);
  for (const EntityId piece : pieces) {
    const std::size_t i = *w.indexOf(piece);
    const double share = static_cast<double>(w.shape(w.bodyShapes()[i]).voxels.occupiedCount()) / 216.0;
    EXPECT_NEAR(w.bodies()[i].material.strength, 10.0 * std::pow(share, 5.0 / 6.0), 1e-12);
  }
}

TEST(FractureWorld, TreeCostIsUnknownUntilMeasuredThenTheLargestRecentRate) {
  TreeCostEstimate cost;
  EXPECT_EQ(cost.seconds(10), std::numeric_limits<double>::infinity());
  cost.record(100, 1e-3);
  EXPECT_DOUBLE_EQ(cost.seconds(50), 0.5e-3);
  cost.record(100, 0.5e-3);  // faster: 10 % of the older rate forgotten
  EXPECT_DOUBLE_EQ(cost.seconds(100), 0.9e-3);
  cost.record(100, 2e-3);    // slower: taken at once
  EXPECT_DOUBLE_EQ(cost.seconds(100), 2e-3);
}

TEST(FractureWorld, OverBudgetTicksBuildOneTreeEach) {
  // Three equal rocks hit the slab alike in the same tick; every tick is over
  // budget, so each tick builds one tree (the queue always moves) and defers
  // the rest. Their pieces are equal: once the first rock's trees exist, the
  // others break in the same tick, for free.
  World w = dropScene(1.0);
  const ShapeId rock = w.bodyShapes()[*w.indexOf(*w.findByName("rock"))];
  for (const double y : {-1.0, 1.0}) {
    EntitySpec s = spec(rock, Vec3(0.0, y, 0.5), "rock" + std::to_string(y > 0), 1.0);
    s.linear_velocity = Vec3(1.0, 0.0, -12.0);
    s.angular_velocity = Vec3(0.0, 3.0, 0.0);
    w.addEntity(s);
  }
  double now = 0.0;
  w.setClock([&now] { return now += 1e-3; });
  std::size_t breaks = 0, most_deferred = 0, trees = 0;
  for (int i = 0; i < 120; ++i) {
    const TickReport r = w.step(kDt, Budget::ofTickSeconds(1e-4));
    EXPECT_LE(r.fracture.piece_trees, 1u) << "tick " << i;
    breaks += r.fracture.fractures;
    trees += r.fracture.piece_trees;
    most_deferred = std::max(most_deferred, r.fracture.fractures_deferred);
  }
  EXPECT_GE(breaks, 3u);
  EXPECT_GE(trees, 2u);
  EXPECT_GE(most_deferred, 2u);
  for (const char* name : {"rock", "rock0", "rock1"}) EXPECT_FALSE(w.findByName(name).has_value()) << name;
}

TEST(FractureWorld, EqualPiecesShareOneShape) {
  World w;
  const ShapeId cube = w.addShape("cube6", solidBox(6, 6, 6));
  EntitySpec s = spec(cube, Vec3::Zero(), "a", 1.0);
  s.pose.orientation = Quat::Identity();
  const EntityId a = w.addEntity(s);
  // Through the centre along x: two 3 x 6 x 6 halves, one shape.
  const std::vector<EntityId> pieces = w.breakEntity(a, Vec3(0.0, 0.0, -0.15), Vec3::UnitY());
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(w.bodyShapes()[*w.indexOf(pieces[0])], w.bodyShapes()[*w.indexOf(pieces[1])]);
  EXPECT_EQ(w.shape(w.bodyShapes()[*w.indexOf(pieces[0])]).voxels.occupiedCount(), 108);
}

TEST(FractureWorld, BadStrengthIsRejectedNamingTheField) {
  World w;
  const ShapeId rock = rockShape(w);
  for (const double bad : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      w.addEntity(spec(rock, Vec3::Zero(), "rock", bad));
      FAIL() << "accepted strength " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "material.strength");
    }
  }
  EXPECT_EQ(w.entityCount(), 0u);
}

TEST(FractureWorld, BadStrengthExponentIsRejectedNamingTheField) {
  for (const double bad : {-0.5, std::numeric_limits<double>::quiet_NaN()}) {
    WorldConfig config;
    config.fracture.strength_exponent = bad;
    EXPECT_TRUE(worldRefuses(config, "fracture.strength_exponent")) << "strength_exponent " << bad;
  }
}

}  // namespace
}  // namespace stc
