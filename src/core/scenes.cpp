// The benchmark scenes as data: which shapes, where, how fast, which walls,
// and a camera that sees them. Walls and floors are static plate tiles.
#include "sphere_tree_collision/scenes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

namespace stc {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;

const std::array<std::pair<SceneKind, const char*>, 6> kScenes{{
    {SceneKind::PackedBox, "packed_box"},
    {SceneKind::BouncingBox, "bouncing_box"},
    {SceneKind::Rockfall, "rockfall"},
    {SceneKind::CornerDrift, "corner_drift"},
    {SceneKind::CubeBox, "cube_box"},
    {SceneKind::Pyramid, "pyramid"}}};

// Seeded draws that mean the same on every standard library (the
// std:: distributions do not promise that).
class Draw {
 public:
  explicit Draw(std::uint32_t seed) : rng_(seed) {}
  double unit() { return static_cast<double>(rng_()) / 4294967296.0; }  // [0, 1)
  double range(double lo, double hi) { return lo + (hi - lo) * unit(); }
  Vec3 direction() {  // uniform on the sphere
    const double z = range(-1.0, 1.0);
    const double phi = range(0.0, 2.0 * kPi);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  Quat rotation() {  // uniform on SO(3) (Shoemake)
    const double u1 = unit(), u2 = range(0.0, 2.0 * kPi), u3 = range(0.0, 2.0 * kPi);
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    return Quat(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3)).normalized();
  }

 private:
  std::mt19937 rng_;
};

std::string keyOf(const char* preset, int resolution, double voxel, std::uint32_t seed) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "scene_%s_r%d_v%.6g_s%u", preset, resolution, voxel, seed);
  return buf;
}

// Collects the entities a scene adds so that a failure removes them all.
class SceneBuilder {
 public:
  SceneBuilder(World& world, SceneSpec& spec) : world_(world), spec_(spec) {}
  ~SceneBuilder() {
    if (committed_) return;
    for (EntityId id : spec_.movers) world_.removeEntity(id);
    for (EntityId id : spec_.walls) world_.removeEntity(id);
    spec_.movers.clear();
    spec_.walls.clear();
  }
  void commit() { committed_ = true; }

  ShapeId preset(const char* name, int resolution, double size, std::uint32_t seed) {
    PresetParams p;
    p.resolution = resolution;
    p.voxel_size = size / resolution;
    p.seed = seed;
    const std::string key = keyOf(name, resolution, p.voxel_size, seed);
    if (const auto found = world_.findShape(key)) return *found;
    return world_.addShape(key, makePreset(name, p, world_.config().voxel_limits));
  }

  void mover(ShapeId shape, const Pose& pose, const Vec3& v, const Vec3& w, const Material& m) {
    EntitySpec e;
    e.shape = shape;
    e.pose = pose;
    e.linear_velocity = v;
    e.angular_velocity = w;
    e.material = m;
    spec_.movers.push_back(world_.addEntity(e));
  }

  // Static plate tiles covering the rectangle centre + [-hu,hu] u + [-hv,hv] v,
  // inner face on that plane, slab behind it (away from `inward`). u, v, inward
  // orthonormal. Square tiles of about `tile` metres, spread to overlap evenly.
  void wall(const Vec3& centre, const Vec3& u, const Vec3& v, double hu, double hv, double tile,
            const Material& m) {
    const int nu = std::max(1, static_cast<int>(std::ceil(2.0 * hu / tile - 1e-9)));
    const int nv = std::max(1, static_cast<int>(std::ceil(2.0 * hv / tile - 1e-9)));
    const double side = std::max(2.0 * hu / nu, 2.0 * hv / nv);
    constexpr int kPlateResolution = 8;  // 8 x 8 x 1 voxels
    const ShapeId plate = preset("plate", kPlateResolution, side, 0);
    const double thickness = world_.shape(plate).voxels.extent().z();
    Vec3 inward = u.cross(v).normalized();
    Mat3 r;  // grid x -> u, grid y -> v, grid z -> the wall normal
    r.col(0) = u;
    r.col(1) = v;
    r.col(2) = inward;
    const Quat q(r);
    auto at = [side](int i, int n, double half) {
      return n == 1 ? 0.0 : -half + 0.5 * side + i * (2.0 * half - side) / (n - 1);
    };
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        EntitySpec e;
        e.shape = plate;
        e.pose.position = centre + at(i, nu, hu) * u + at(j, nv, hv) * v - 0.5 * thickness * inward;
        e.pose.orientation = q;
        e.is_static = true;
        e.closed_faces = faceBit(2, false);  // one-sided: the back never pushes a body out
        e.material = m;
        spec_.walls.push_back(world_.addEntity(e));
      }
    }
  }

  // Walls with inner faces on the box [c - h, c + h]: the floor in tiles of
  // `floor_tile`, the four sides (and the ceiling, unless open) of `wall_tile`.
  void box(const Vec3& c, const Vec3& h, double floor_tile, double wall_tile, bool open_top,
           const Material& m) {
    const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
    wall(c - h.z() * z, x, y, h.x(), h.y(), floor_tile, m);                // floor, normal +z
    if (!open_top) wall(c + h.z() * z, y, x, h.y(), h.x(), wall_tile, m);  // ceiling, normal -z
    wall(c - h.x() * x, y, z, h.y(), h.z(), wall_tile, m);   // normal +x
    wall(c + h.x() * x, z, y, h.z(), h.y(), wall_tile, m);   // normal -x
    wall(c - h.y() * y, z, x, h.z(), h.x(), wall_tile, m);   // normal +y
    wall(c + h.y() * y, x, z, h.x(), h.z(), wall_tile, m);   // normal -y
  }

 private:
  World& world_;
  SceneSpec& spec_;
  bool committed_ = false;
};

// A camera at `direction` from the centre, far enough for a ball of `radius` to fit the view.
Camera cameraOn(const Vec3& centre, double radius, const Vec3& direction) {
  Camera c;
  const double distance = radius / std::sin(0.5 * c.fov_y_deg * kPi / 180.0);
  c.camera_to_world = opticalLookAt(centre + distance * direction.normalized(), centre);
  return c;
}

int defaultCount(SceneKind kind) {
  switch (kind) {
    case SceneKind::PackedBox: return 500;
    case SceneKind::BouncingBox: return 100;
    case SceneKind::Rockfall: return 200;
    case SceneKind::CornerDrift: return 500;
    case SceneKind::CubeBox: return 1000;
    case SceneKind::Pyramid: return 5050;  // a base of 100
  }
  return 100;
}

// Lattice of `count` cells, `per_side` along x and y, filled x, then y, then z.
Vec3 latticeCell(int index, int per_side, double spacing) {
  const int i = index % per_side, j = (index / per_side) % per_side, k = index / (per_side * per_side);
  return Vec3(i + 0.5, j + 0.5, k + 0.5) * spacing;
}

// PackedBox / CornerDrift / BouncingBox / CubeBox: entities on a cubic lattice in a closed box.
void boxScene(SceneBuilder& b, SceneSpec& spec, const SceneParams& p, int count, Draw& draw) {
  struct Style {
    double spacing;      // lattice spacing / entity size
    double speed;        // initial speed / params.speed
    double spin;         // rad/s, max initial angular speed
    Material material;
  };
  Style s{1.1, 1.0, 2.0, Material{0.9, 0.1}};                            // packed: always colliding
  if (spec.kind == SceneKind::BouncingBox) s = Style{2.5, 2.0, 3.0, Material{0.7, 0.3}};
  if (spec.kind == SceneKind::CornerDrift) s = Style{1.6, 0.3, 1.0, Material{0.3, 0.5}};
  // Cubes start apart: a cube turned any way (diagonal sqrt(3)) fits a cell of 2.
  if (spec.kind == SceneKind::CubeBox) s = Style{2.0, 0.5, 1.0, Material{0.2, 0.5}};

  const int per_side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count)) - 1e-9));
  const double spacing = s.spacing * p.entity_size;
  const double half = 0.5 * per_side * spacing;
  const Vec3 centre = Vec3::Constant(half);  // box [0, 2 half]^3
  const double tile = std::max(p.entity_size * 2.5, 2.0 * half / 4.0);
  b.box(centre, Vec3::Constant(half), tile, tile, false, s.material);

  // Homogeneous for the paper's scenes; a cycle of presets for the bouncing box.
  static const char* kMixed[] = {"cube", "rock", "rod", "L", "ring", "sphere"};
  for (int i = 0; i < count; ++i) {
    const char* name = spec.kind == SceneKind::BouncingBox ? kMixed[i % 6]
                       : spec.kind == SceneKind::CubeBox   ? "cube"
                                                           : "rock";
    const ShapeId shape = b.preset(name, p.resolution, p.entity_size, p.seed);
    Pose pose;
    pose.position = latticeCell(i, per_side, spacing);
    pose.orientation = draw.rotation();
    const Vec3 v = draw.direction() * (p.speed * s.speed * draw.range(0.5, 1.0));
    const Vec3 w = draw.direction() * draw.range(0.0, s.spin);
    b.mover(shape, pose, v, w, s.material);
  }
  spec.bounds.min = Vec3::Zero();
  spec.bounds.max = Vec3::Constant(2.0 * half);
  spec.camera = cameraOn(centre, std::sqrt(3.0) * half * 0.85, Vec3(0.55, -1.0, 0.45));
}

// Rockfall: a straight ravine (floor, two side walls, a back wall) sloping down
// along +x onto a flat run-out; rocks of four seeded shapes start stacked
// above its upper half and fall, tumble and bounce off each other. A walled
// tray under the whole scene (its floor is the run-out) catches what rolls off
// the run-out or spills over the ravine walls, so every rock ends in the pile.
// Up to 200 rocks the ravine has its base size; beyond, every length grows with
// the cube root of the count, so the starting column keeps to the same share
// of the ravine's depth (at 5,000 rocks a 2.9 times larger ravine, not a 59 m column).
void rockfall(SceneBuilder& b, SceneSpec& spec, const SceneParams& p, int count, Draw& draw) {
  const double size = p.entity_size;
  const double scale = std::max(1.0, std::cbrt(count / 200.0));
  const double length = 30.0 * size * scale, width = 6.0 * size * scale, height = 10.0 * size * scale;
  const double slope = 25.0 * kPi / 180.0;
  // Rolling resistance 0.2 (Material): a rock rolls down slopes steeper than
  // atan 0.2 = 11 deg (the 25 deg floor, at 5 g (sin - 0.2 cos) / 7 =
  // 1.7 m/s^2), and a pile of thousands comes to rest (docs/sleeping.md:
  // without it rocks kept rocking and creeping in the pile; 0.3 slowed the
  // fall too much for test_scenes' rocks to reach the run-out in 4 s).
  const Material rock{0.3, 0.6, 0.0, 0.2};
  // Ravine frame: x downhill along the floor, y across, z up from the floor.
  const Quat tilt(Eigen::AngleAxisd(slope, Vec3::UnitY()));
  const Vec3 top(0.0, 0.0, length * std::sin(slope));
  const Vec3 ex = tilt * Vec3::UnitX(), ey = tilt * Vec3::UnitY(), ez = tilt * Vec3::UnitZ();
  const double tile = 2.5 * size * scale;
  const Vec3 mid = top + 0.5 * length * ex;
  b.wall(mid, ex, ey, 0.5 * length, 0.5 * width, tile, rock);                                     // floor
  b.wall(mid - 0.5 * width * ey + 0.5 * height * ez, ez, ex, 0.5 * height, 0.5 * length, tile, rock);  // +y facing
  b.wall(mid + 0.5 * width * ey + 0.5 * height * ez, ex, ez, 0.5 * length, 0.5 * height, tile, rock);  // -y facing
  b.wall(top + 0.5 * height * ez, ey, ez, 0.5 * width, 0.5 * height, tile, rock);               // back, facing +x

  // Tray: floor at z = 0 from behind the ravine's back wall to the run-out's
  // end, three ravine widths across, walls as high as the ravine's; coarser
  // tiles on its walls, which only catch.
  const Vec3 foot = top + length * ex;
  const double runout = 16.0 * size * scale;
  const Vec3 lo(-size * scale, -1.5 * width, 0.0), hi(foot.x() + runout, 1.5 * width, height);
  b.box(0.5 * (lo + hi), 0.5 * (hi - lo), tile, 2.0 * tile, true, rock);

  // Rocks: a lattice in the ravine frame over the upper half, layered upward.
  const double spacing = 1.3 * size;
  const int along = std::max(1, static_cast<int>(0.5 * length / spacing));
  const int across = std::max(1, static_cast<int>((width - 0.5 * size) / spacing));
  std::array<ShapeId, 4> shapes{};
  for (std::uint32_t k = 0; k < shapes.size(); ++k) {
    shapes[k] = b.preset("rock", p.resolution, size, p.seed * 4 + k);
  }
  for (int i = 0; i < count; ++i) {
    const int a = i % along, across_i = (i / along) % across, layer = i / (along * across);
    const Vec3 local(size + (a + 0.5) * spacing, -0.5 * (across - 1) * spacing + across_i * spacing,
                     size + (layer + 0.5) * spacing);
    Pose pose;
    pose.position = top + local.x() * ex + local.y() * ey + local.z() * ez;
    pose.orientation = draw.rotation();
    const Vec3 v = p.speed * (0.5 * ex + 0.2 * draw.direction());
    const Vec3 w = draw.direction() * draw.range(0.0, 2.0);
    b.mover(shapes[static_cast<std::size_t>(i) % shapes.size()], pose, v, w, rock);
  }
  // Inside the tray, up to the top of the ravine's back wall.
  spec.bounds.min = lo;
  spec.bounds.max = Vec3(hi.x(), hi.y(), top.z() + height + 4.0 * size);
  const Vec3 look = top + 0.6 * length * ex + 0.3 * height * ez;
  spec.camera = cameraOn(look, 0.45 * length, Vec3(0.35, -1.0, 0.55));
  spec.dt = 1.0 / 60.0;
}

// Pyramid: the layout of Box2D's large_pyramid benchmark, in one vertical
// plane (x along the rows, z up): a base row of cubes side by side on a static
// floor, each row above one cube shorter and shifted half a cube along x, so
// every cube rests on two below. The cubes start touching and at rest, axis
// aligned. `count` fills the rows from the base up: the base is the shortest
// that holds them all (5,050 cubes: 100), the top row may be short. The floor
// reaches a pyramid's width beyond each side along x (Box2D's ground is twice
// the pyramid's width) and half its width to each side across; its edges are
// the bounds. `speed` and `seed` are not used.
void pyramid(SceneBuilder& b, SceneSpec& spec, const SceneParams& p, int count) {
  const double size = p.entity_size;
  int base = 1;
  while (base * (base + 1) / 2 < count) ++base;
  const double half_base = 0.5 * base * size;
  const Material cube{0.0, 0.6};  // Box2D's default friction, no bounce
  const double hx = 2.0 * half_base, hy = std::max(2.0 * size, 0.5 * half_base);
  const double tile = std::max(2.5 * size, hx / 8.0);
  b.wall(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), hx, hy, tile, cube);
  const ShapeId shape = b.preset("cube", p.resolution, size, p.seed);
  int placed = 0;
  for (int row = 0; placed < count; ++row) {
    for (int j = 0; j < base - row && placed < count; ++j, ++placed) {
      Pose pose;
      pose.position = Vec3(-half_base + (0.5 * (row + 1) + j) * size, 0.0, (row + 0.5) * size);
      b.mover(shape, pose, Vec3::Zero(), Vec3::Zero(), cube);
    }
  }
  const double height = base * size;
  spec.bounds.min = Vec3(-hx, -hy, 0.0);
  spec.bounds.max = Vec3(hx, hy, height + size);
  spec.camera = cameraOn(Vec3(0.0, 0.0, 0.4 * height), 0.65 * height, Vec3(0.3, -1.0, 0.35));
  spec.dt = 1.0 / 60.0;
}

}  // namespace

SceneKind parseScene(const std::string& name) {
  std::string allowed;
  for (const auto& [kind, text] : kScenes) {
    if (name == text) return kind;
    allowed += (allowed.empty() ? "" : ", ") + std::string(text);
  }
  throw InputError("scene", "unknown value '" + name + "' (expected one of: " + allowed + ")");
}

const char* toString(SceneKind kind) {
  for (const auto& [k, text] : kScenes) {
    if (k == kind) return text;
  }
  return "?";
}

Vec3 sceneGravity(SceneKind kind) {
  switch (kind) {
    case SceneKind::PackedBox: return Vec3::Zero();
    case SceneKind::BouncingBox:
    case SceneKind::Rockfall:
    case SceneKind::CubeBox:
    case SceneKind::Pyramid: return Vec3(0.0, 0.0, -kG);
    case SceneKind::CornerDrift: return -kG * Vec3::Ones().normalized();  // into the box's (0,0,0) corner
  }
  return Vec3::Zero();
}

SceneSpec populateScene(World& world, SceneKind kind, const SceneParams& params) {
  const int count = params.entities > 0 ? params.entities : defaultCount(kind);
  if (params.entities < 0) throw InputError("entities", "must be >= 0 (0: the scene's default)");
  if (!std::isfinite(params.entity_size) || params.entity_size <= 0.0) {
    throw InputError("entity_size", "must be finite and > 0");
  }
  if (params.resolution < 2 || params.resolution > 64) {
    throw InputError("resolution", "must be in [2, 64]");
  }
  if (!std::isfinite(params.speed) || params.speed < 0.0) {
    throw InputError("speed", "must be finite and >= 0");
  }
  if ((world.config().gravity - sceneGravity(kind)).norm() > 1e-9) {
    throw InputError("gravity", std::string("the world's gravity must be sceneGravity(") +
                                    toString(kind) + ")");
  }
  if (world.entityCount() + static_cast<std::size_t>(count) > world.config().max_entities) {
    throw InputError("entities", "the scene would exceed the world's max_entities");
  }

  SceneSpec spec;
  spec.kind = kind;
  spec.gravity = sceneGravity(kind);
  SceneBuilder builder(world, spec);
  Draw draw(params.seed);
  if (kind == SceneKind::Rockfall) {
    rockfall(builder, spec, params, count, draw);
  } else if (kind == SceneKind::Pyramid) {
    pyramid(builder, spec, params, count);
  } else {
    boxScene(builder, spec, params, count, draw);
  }
  builder.commit();
  return spec;
}

SceneWorld makeSceneWorld(SceneKind kind, const SceneParams& params, WorldConfig config) {
  config.gravity = sceneGravity(kind);
  SceneWorld scene{World(config), SceneSpec{}};
  scene.spec = populateScene(scene.world, kind, params);
  scene.world.perception().setCamera(scene.spec.camera);
  return scene;
}

}  // namespace stc
