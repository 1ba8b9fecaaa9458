// Static geometry made of tiles holds a body as one piece would: the faces of
// static voxel boxes that solid covers (the body's own voxels, a flush
// neighbour tile, a one-sided wall's back) never give a contact normal.
#include "shape_bounds.hpp"
#include "sphere_tree_collision/world.hpp"
#include "static_cover.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace stc;

namespace {

constexpr double kCell = 0.25;   // floor voxels: 8 x 8 x 1 tiles of 2 m, 25 cm thick
constexpr double kVoxel = 0.05;  // the cube: 8 voxels, 40 cm
constexpr double kHalfCube = 0.2;

ShapeId solidBox(World& world, const std::string& key, int nx, int ny, int nz, double voxel) {
  return world.addShape(key, VoxelShape::create(nx, ny, nz, voxel,
                                                std::vector<std::uint8_t>(static_cast<std::size_t>(nx * ny * nz), 1)));
}

// Static tiles along x with their top faces at z = 0: `count` of them, abutting
// (gap 0) or `gap` metres apart; tile 0 spans x in [-2, 0] when count is 2.
void addTiles(World& world, int count, double gap = 0.0, std::uint8_t closed = 0) {
  const ShapeId tile = solidBox(world, "tile", 8, 8, 1, kCell);
  const double side = 8 * kCell;
  for (int i = 0; i < count; ++i) {
    EntitySpec e;
    e.shape = tile;
    e.pose.position = Vec3((i - 0.5 * (count - 1)) * (side + gap), 0.0, -0.5 * kCell);
    e.is_static = true;
    e.closed_faces = closed;
    world.addEntity(e);
  }
}

// A cube over the seam x = 0, `sunk` of its height below the floor's top.
std::size_t addSunkCube(World& world, double sunk, double x = 0.0) {
  EntitySpec cube;
  cube.shape = solidBox(world, "cube", 8, 8, 8, kVoxel);
  cube.pose.position = Vec3(x, 0.0, kHalfCube - sunk * 2.0 * kHalfCube);
  return *world.indexOf(world.addEntity(cube));
}

World gravityWorld() {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  return World(config);
}

// The masks of body 0 (a tile) as the World builds them, every static body closed by `closed`.
std::vector<std::uint8_t> masksOfFirstTile(const World& world, std::uint8_t closed = 0, std::uint8_t* root = nullptr) {
  std::vector<ShapeBounds> bounds;
  std::vector<CoverShape> shapes;
  bounds.reserve(world.shapeCount());
  for (ShapeId s = 0; s < world.shapeCount(); ++s) {
    const ShapeInfo& info = world.shape(s);
    bounds.push_back(makeShapeBounds(info.tree, &info.voxels, info.body_origin));
  }
  for (ShapeId s = 0; s < world.shapeCount(); ++s) {
    shapes.push_back(CoverShape{&world.shape(s).voxels, world.shape(s).body_origin, &bounds[s]});
  }
  StaticCover cover;
  for (const BodyState& b : world.bodies()) cover.add(b, b.is_static ? closed : 0);
  EXPECT_TRUE(cover.update(world.bodies(), world.bodyShapes(), shapes));
  EXPECT_FALSE(cover.update(world.bodies(), world.bodyShapes(), shapes)) << "nothing moved: no rebuild";
  const std::uint8_t* masks = cover.of(0);
  if (masks == nullptr) return {};
  const std::size_t nodes = world.shape(world.bodyShapes()[0]).tree.nodes().size();
  if (root != nullptr) *root = masks[0];
  return std::vector<std::uint8_t>(masks, masks + nodes);
}

// Leaves of tile 0 whose box ends at the tile's +x rim have that face covered
// exactly when the next tile lies flush against it.
int rimLeavesCovered(const World& world, const std::vector<std::uint8_t>& masks) {
  const ShapeInfo& info = world.shape(world.bodyShapes()[0]);
  const ShapeBounds bounds = makeShapeBounds(info.tree, &info.voxels, info.body_origin);
  int covered = 0, rim = 0;
  for (std::size_t n = 0; n < info.tree.nodes().size(); ++n) {
    if (info.tree.node(static_cast<std::int32_t>(n)).child_count != 0) continue;
    const double right = info.tree.node(static_cast<std::int32_t>(n)).centre.x() + bounds.box_offset[n].x() +
                         bounds.box_half[n].x();
    if (std::abs(right - 4 * kCell) > 1e-9) continue;  // body frame: the tile spans x in [-1, 1]
    ++rim;
    if ((masks[n] & faceBit(0, true)) != 0) ++covered;
  }
  EXPECT_GT(rim, 0);
  return rim == 0 ? -1 : (covered == rim ? 1 : (covered == 0 ? 0 : -1));
}

}  // namespace

TEST(StaticCover, MarksFacesInsideTheTileAndAgainstAFlushNeighbourOnly) {
  World apart = gravityWorld();
  addTiles(apart, 2, /*gap=*/0.1);
  const std::vector<std::uint8_t> alone = masksOfFirstTile(apart);
  ASSERT_FALSE(alone.empty()) << "inner faces between a tile's own leaves are covered";
  EXPECT_EQ(rimLeavesCovered(apart, alone), 0) << "a rim with a gap beyond is a surface";

  World flush = gravityWorld();
  addTiles(flush, 2);
  std::uint8_t root = 0;
  const std::vector<std::uint8_t> joined = masksOfFirstTile(flush, 0, &root);
  EXPECT_EQ(rimLeavesCovered(flush, joined), 1) << "the rim against the next tile is covered";
  for (const std::uint8_t m : joined) {
    EXPECT_EQ(m & faceBit(2, true), 0) << "the top is open";
    EXPECT_EQ(m & faceBit(2, false), 0) << "the bottom is open unless closed";
  }
  EXPECT_EQ(root & faceBit(0, true), faceBit(0, true)) << "the whole tile's +x face lies against the next";
  EXPECT_EQ(root & faceBit(0, false), 0) << "its -x face is the floor's outer edge";

  World one_sided = gravityWorld();
  addTiles(one_sided, 2, 0.0, faceBit(2, false));
  for (const std::uint8_t m : masksOfFirstTile(one_sided, faceBit(2, false))) EXPECT_NE(m & faceBit(2, false), 0);
}

// Masks of every body as a cover built at once from `bodies` gives them.
std::vector<std::vector<std::uint8_t>> maskTable(const StaticCover& cover, const std::vector<BodyState>& bodies,
                                                 const World& world, const std::vector<std::uint32_t>& shapes_of) {
  std::vector<std::vector<std::uint8_t>> table;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const std::uint8_t* m = cover.of(i);
    const std::size_t nodes = world.shape(shapes_of[i]).tree.nodes().size();
    table.push_back(m == nullptr ? std::vector<std::uint8_t>{} : std::vector<std::uint8_t>(m, m + nodes));
  }
  return table;
}

// A cover kept up to date tile by tile (spawned, moved, removed) holds the
// masks one built from scratch would: only the tiles near a change are
// measured again, and none that should be is missed.
TEST(StaticCover, KeptUpToDateItEqualsACoverBuiltAtOnce) {
  World world = gravityWorld();
  addTiles(world, 1);  // the tile shape; its body is dropped from the lists below
  std::vector<ShapeBounds> bounds;
  bounds.push_back(makeShapeBounds(world.shape(0).tree, &world.shape(0).voxels, world.shape(0).body_origin));
  const std::vector<CoverShape> shapes{CoverShape{&world.shape(0).voxels, world.shape(0).body_origin, &bounds[0]}};
  std::vector<BodyState> bodies;
  std::vector<std::uint32_t> shapes_of;
  StaticCover kept;
  const auto fresh = [&] {
    StaticCover built;
    for (const BodyState& b : bodies) built.add(b);
    built.update(bodies, shapes_of, shapes);
    return maskTable(built, bodies, world, shapes_of);
  };
  const auto tileAt = [&](double x, double y) {
    BodyState b = world.bodies()[0];
    b.pose.position = Vec3(x, y, -0.5 * kCell);
    bodies.push_back(b);
    shapes_of.push_back(0);
    kept.add(b);
  };
  // A 3 x 2 floor laid one tile per update, then one far away.
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 3; ++i) {
      tileAt(2.0 * i, 2.0 * j);
      kept.update(bodies, shapes_of, shapes);
      ASSERT_EQ(maskTable(kept, bodies, world, shapes_of), fresh()) << "after tile " << bodies.size();
    }
  }
  tileAt(40.0, 0.0);
  kept.update(bodies, shapes_of, shapes);
  EXPECT_EQ(maskTable(kept, bodies, world, shapes_of), fresh());
  // The middle tile of the first row moved away: its neighbours' rims open.
  bodies[1].pose.position.z() -= 5.0;
  EXPECT_TRUE(kept.update(bodies, shapes_of, shapes));
  EXPECT_EQ(maskTable(kept, bodies, world, shapes_of), fresh());
  // A corner tile removed (swap-remove, as the World does: the far tile takes its place).
  kept.remove(0, bodies.size() - 1);
  bodies[0] = bodies.back();
  bodies.pop_back();
  shapes_of.pop_back();
  EXPECT_TRUE(kept.update(bodies, shapes_of, shapes));
  EXPECT_EQ(maskTable(kept, bodies, world, shapes_of), fresh());
  EXPECT_FALSE(kept.update(bodies, shapes_of, shapes));
}

// The bug this fixes: a cube pressed into the seam of two tiles was pushed
// sideways by both tiles' rims (5.8 cm at 30 % sunk) or, at 50 %, fell through.
TEST(StaticCover, ACubePressedIntoTheSeamOfTwoTilesRisesStraightUp) {
  for (const double sunk : {0.2, 0.3, 0.35}) {
    for (const double x : {0.0, 0.05, 0.1}) {
      World world = gravityWorld();
      addTiles(world, 2);
      const std::size_t cube = addSunkCube(world, sunk, x);
      for (int t = 0; t < 240; ++t) world.step(1.0 / 60.0, Budget::unlimited());
      const BodyState& b = world.bodies()[cube];
      SCOPED_TRACE("sunk " + std::to_string(sunk) + ", x " + std::to_string(x));
      EXPECT_NEAR(b.pose.position.z(), kHalfCube, 0.01) << "resting on top";
      EXPECT_NEAR(b.pose.position.x(), x, 0.002) << "not pushed along the floor";
      EXPECT_NEAR(b.pose.position.y(), 0.0, 0.002);
      EXPECT_LT(b.linear_velocity.norm(), 0.05);
    }
  }
}

TEST(StaticCover, AOneSidedFloorPushesADeepCubeBackUpEvenWithOneSolverPass) {
  for (const Budget& budget : {Budget::unlimited(), Budget::ofSolverIterations(1)}) {
    for (const double sunk : {0.5, 0.6}) {  // 20 and 24 cm into a 25 cm floor
      for (const double x : {0.0, 0.1}) {
        World world = gravityWorld();
        addTiles(world, 2, 0.0, faceBit(2, false));
        const std::size_t cube = addSunkCube(world, sunk, x);
        for (int t = 0; t < 600; ++t) world.step(1.0 / 60.0, budget);
        const BodyState& b = world.bodies()[cube];
        SCOPED_TRACE("sunk " + std::to_string(sunk) + ", x " + std::to_string(x) + ", passes " +
                     std::to_string(budget.solver_iterations));
        EXPECT_NEAR(b.pose.position.z(), kHalfCube, 0.01) << "back on top, not through the floor";
        EXPECT_LT(b.linear_velocity.norm(), 0.05);
      }
    }
  }
}

// Under a budget a pair is taken at its frontier: with no sphere test, at the
// roots. A cube whose centre is below the middle of a one-sided floor has its
// root under the floor's root, so the floor's face towards it is the closed
// back; the open top must give the normal (up), not the line of centres
// (down, out). The overlap is the roots', not proven of the surfaces, so the
// contact pushes nothing apart: the cube is held where it is, neither sinking
// out through the back nor lifted (resolved at the leaves, it comes back on
// top: the test above).
TEST(StaticCover, AOneSidedFloorHoldsADeepCubeFromItsRootsAlone) {
  for (const double x : {0.0, 0.1, 1.0}) {
    World world = gravityWorld();  // policy accept: untested pairs give contacts at their roots
    addTiles(world, 2, 0.0, faceBit(2, false));
    const std::size_t cube = addSunkCube(world, 0.9, x);  // centre 16 cm below the top, 3.5 below the middle
    const double start_z = world.bodies()[cube].pose.position.z();
    SCOPED_TRACE("x " + std::to_string(x));
    world.step(1.0 / 60.0, Budget::ofSphereTests(0));
    int floor_contacts = 0;
    for (const Contact& c : world.contacts()) {
      if (c.index_a != cube && c.index_b != cube) continue;
      ++floor_contacts;
      const Vec3 towards_cube = c.index_b == cube ? c.normal : Vec3(-c.normal);
      EXPECT_GT(towards_cube.z(), 0.99) << "the floor's open top, not its closed back";
      EXPECT_FALSE(c.resolved);
      EXPECT_GE(c.separation, 0.0) << "an unproven overlap pushes nothing apart";
    }
    EXPECT_GT(floor_contacts, 0);
    for (int t = 1; t < 300; ++t) world.step(1.0 / 60.0, Budget::ofSphereTests(0));
    const BodyState& b = world.bodies()[cube];
    EXPECT_NEAR(b.pose.position.z(), start_z, 0.01) << "held: not out through the back, not pushed up";
    EXPECT_LT(b.linear_velocity.norm(), 0.05);
  }
}

// A free rim stays a surface: a cube sliding at the floor's outer edge from
// the side is stopped by it, not lifted onto the floor.
TEST(StaticCover, AFreeRimStillStopsACubeFromTheSide) {
  WorldConfig config;  // no gravity
  World world(config);
  addTiles(world, 2, 0.0, faceBit(2, false));
  EntitySpec cube;
  cube.shape = solidBox(world, "cube", 8, 8, 8, kVoxel);
  cube.pose.position = Vec3(4.0 * kCell * 2.0 + kHalfCube + 0.05, 0.0, -0.5 * kCell);  // beside tile 1's +x rim
  cube.linear_velocity = Vec3(-1.0, 0.0, 0.0);
  const std::size_t index = *world.indexOf(world.addEntity(cube));
  const double rim = 4.0 * kCell * 2.0;
  for (int t = 0; t < 60; ++t) {
    world.step(1.0 / 60.0, Budget::unlimited());
    const BodyState& b = world.bodies()[index];
    ASSERT_GT(b.pose.position.x() - kHalfCube, rim - 0.05) << "tick " << t << ": into the tile";
    ASSERT_NEAR(b.pose.position.z(), -0.5 * kCell, 0.05) << "tick " << t << ": lifted";
  }
  EXPECT_GE(world.bodies()[index].linear_velocity.x(), 0.0) << "stopped or bounced back";
}

TEST(StaticCover, ClosedFacesAreForStaticBodiesAndValidFacesOnly) {
  World world = gravityWorld();
  addTiles(world, 1);
  const std::size_t before = world.entityCount();
  EntitySpec moving;
  moving.shape = solidBox(world, "cube", 8, 8, 8, kVoxel);
  moving.closed_faces = faceBit(2, false);
  try {
    world.addEntity(moving);
    FAIL() << "a movable body with closed faces was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "closed_faces");
  }
  EntitySpec wall = moving;
  wall.is_static = true;
  wall.closed_faces = 64;
  try {
    world.addEntity(wall);
    FAIL() << "a mask beyond the six faces was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "closed_faces");
  }
  EXPECT_EQ(world.entityCount(), before);
  wall.closed_faces = kAllFaces;
  EXPECT_NO_THROW(world.addEntity(wall));
}
