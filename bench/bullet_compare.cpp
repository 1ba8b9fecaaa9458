// Side by side with Bullet 3.24 (issue 9, item 6): each built-in scene run by
// this package's World (WorldConfig defaults, unlimited budget) and by
// Bullet's btDiscreteDynamicsWorld with its defaults (dynamic AABB tree broad
// phase, sequential impulses with 10 iterations and split impulse, sleeping
// on), on the same bodies: same poses, velocities, masses, inertia, gravity,
// dt and materials. Bullet gets each voxel shape three ways, one run each:
//   compound  btCompoundShape of the shape's leaf spheres (its SphereTree);
//   hull      btConvexHullShape of the corners of the surface voxels, shrunk
//             by its collision margin (Bullet's default 0.04 m, at most a
//             quarter of the hull's inner radius) so that hull + margin is
//             the voxel hull;
//   lean      Bullet at its best: a full box of voxels (the cubes, the wall
//             plates) as a btBoxShape; any other shape as a btConvexHullShape
//             of its surface-voxel corners reduced by optimizeConvexHull()
//             to the hull's vertices, with a 1 cm margin (so its surface is
//             1 cm outside the voxel hull).
// Walls (static plates) are built the same way as the movers in each run.
// Each run prints, per shape, what Bullet got: spheres, or vertices and margin.
// Materials combine as in this package: restitution max, friction sqrt(a b),
// rolling resistance the larger (see combinedRolling).
//
// Per tick: wall and thread-CPU time of one step, each engine's phase split
// (this package's TickReport; Bullet's own profile zones: its collision
// detection, its constraint solve, the rest), and sanity figures over the movers: mean stored speed
// against mean |dx|/dt (they agree when stored velocity is real motion),
// final mean speed, bodies out of the scene's bounds (at the end; ever).
// Ends with one SUMMARY line per scene: this package's thread-CPU p50 and
// p99, Bullet's best (lowest) thread-CPU p50, which variant that was, and the
// ratio of the two p50s.
//
// Usage: bench_bullet_compare [--seconds S] [--settle S] [--scenes LIST] [--variants LIST] [--iterations N]
//                             [--reuse T[,T...]] [--solver NAME[,NAME...]] [--markdown FILE]
//   --seconds   simulated time per run (default 10)
//   --settle    simulated time run first, untimed (default 0): with it the timed
//               ticks are those of a settling scene, where both engines put
//               islands at rest to sleep (docs/sleeping.md)
//   --scenes    comma separated, each NAME or NAME:BODIES (default: corner_drift:500,
//               packed_box:500, rockfall:1000, rockfall:5000, cube_box:10000,
//               pyramid:5050; a bare NAME picks that scene's cases from the default list)
//   --variants  Bullet shapes to run: compound,hull,lean (default all three; empty: none)
//   --bullet-only  skip this package's run (to run the engines apart, in parallel)
//   --smoke     every scene at 100 bodies at most, 0.05 s, no settling: that the bench runs, scripts/bench_smoke.sh
//   --iterations N  this package's velocity and position iterations per tick
//               (ResponseOptions::iterations; default: the World's). Bullet
//               runs its default 10 always: --iterations 10 compares the two
//               at the same solver effort. The SUMMARY lines say which was used.
//   --solver NAME  this package's solver (ResponseOptions::solver: sequential, jacobi,
//               soft; default: the World's, sequential). The SUMMARY lines say so. A list
//               (--solver sequential,soft) runs one World per solver side by side, as --reuse's list.
//   --reuse T   this package carries a resting pair's contacts over while its bodies
//               drift less than T of a leaf radius (ResponseOptions::reuse_tolerance;
//               default: the World's). The SUMMARY lines say so. A list (--reuse 0,0.05)
//               runs one World per value side by side, in turns of 10 ticks (so a
//               loaded machine weighs on each alike), with their phases timed in
//               thread-CPU (World::setClock), and prints them in one more table: the
//               whole tick, narrow phase, contact building and solve, and the share
//               of colliding pairs whose contacts were carried over.
// Where the response's time goes (instruction counts, stable on a loaded machine;
// docs/response.md, "Cost of the response"):
//   valgrind --tool=callgrind --toggle-collect='stc::Physics::buildContacts*' --toggle-collect='stc::Physics::solve*'
//     bench_bullet_compare --seconds 3 --scenes rockfall:1000 --variants ""
//   (one command line; callgrind_annotate --inclusive=yes on its output file)
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "scene_cases.hpp"
#include "tick_clock.hpp"

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionDispatch/btManifoldResult.h>
#include <LinearMath/btConvexHullComputer.h>

#include <Eigen/Eigenvalues>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace stc;
using stc_bench::maxOf;
using stc_bench::meanOf;
using stc_bench::percentile;

using Case = stc_bench::SceneCase;
const std::vector<Case> kDefaultCases{{SceneKind::CornerDrift, 500},
                                      {SceneKind::PackedBox, 500},
                                      {SceneKind::Rockfall, 1000},
                                      {SceneKind::Rockfall, 5000},
                                      {SceneKind::CubeBox, 10000},
                                      {SceneKind::Pyramid, 5050}};

// What one engine did over one run of one scene.
struct Run {
  std::string engine;
  std::vector<double> wall, cpu;                          // s per tick
  // Wall s per tick of each phase. Both engines: `detection` (this package:
  // broad phase, sweep, narrow phase and building the contacts; Bullet: its
  // broad and narrow phase and contact manifolds) and `solve`. This package
  // also splits them (integrate ... building); Bullet's `rest` is all else
  // (integration, islands, activation).
  std::vector<double> integrate, broad, sweep, narrow, building, detection, solve, rest;
  std::vector<double> contacts;                           // per tick (this package)
  std::vector<double> reused;  // per tick (this package): share of the colliding pairs carried over
  bool cpu_phases = false;     // this package's phases in thread-CPU s (side by side), else wall
  double stored_speed = 0.0;  // mean over ticks and movers of |v|
  double moved_speed = 0.0;   // mean over ticks and movers of |dx| / dt
  double final_speed = 0.0;   // mean |v| after the last tick
  int out_end = 0, out_ever = 0, non_finite = 0;
  int sleeping = -1;          // movers asleep at the end
};

// Follows the movers' centres tick by tick for the sanity figures.
class MotionCheck {
 public:
  MotionCheck(const Aabb& bounds, double dt) : bounds_(bounds), dt_(dt) {}
  void start(const std::vector<Vec3>& positions) {
    last_ = positions;
    ever_out_.assign(positions.size(), 0);
  }
  void tick(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities) {
    for (std::size_t i = 0; i < positions.size(); ++i) {
      stored_sum_ += velocities[i].norm();
      moved_sum_ += (positions[i] - last_[i]).norm() / dt_;
      if (!inside(positions[i])) ever_out_[i] = 1;
    }
    samples_ += positions.size();
    last_ = positions;
    last_velocities_ = velocities;
  }
  void finish(Run& run) const {
    const double n = static_cast<double>(std::max<std::size_t>(samples_, 1));
    run.stored_speed = stored_sum_ / n;
    run.moved_speed = moved_sum_ / n;
    double speed = 0.0;
    for (std::size_t i = 0; i < last_.size(); ++i) {
      speed += last_velocities_.empty() ? 0.0 : last_velocities_[i].norm();
      if (!inside(last_[i])) ++run.out_end;
      if (ever_out_[i]) ++run.out_ever;
      if (!last_[i].allFinite()) ++run.non_finite;
    }
    run.final_speed = last_.empty() ? 0.0 : speed / static_cast<double>(last_.size());
  }

 private:
  bool inside(const Vec3& p) const {
    return p.allFinite() && bounds_.contains(p);
  }
  Aabb bounds_;
  double dt_;
  std::vector<Vec3> last_, last_velocities_;
  std::vector<char> ever_out_;
  double stored_sum_ = 0.0, moved_sum_ = 0.0;
  std::size_t samples_ = 0;
};

// What this package's runs change from the World's defaults.
struct PackageOptions {
  int iterations = 0;      // > 0: solver iterations instead of the default
  double reuse = -1.0;     // >= 0: ResponseOptions::reuse_tolerance
  std::string solver;      // non-empty: ResponseOptions::solver by name
  std::string label() const {
    std::string out = "this package";
    if (!solver.empty()) out += ", " + solver + " solver";
    if (iterations > 0) out += ", " + std::to_string(iterations) + " iterations";
    if (reuse >= 0.0) out += ", reuse " + shortNumber(reuse);
    return out;
  }
  std::string summary() const {
    std::string out;
    if (!solver.empty()) out += " solver=" + solver;
    if (iterations > 0) out += " iterations=" + std::to_string(iterations);
    if (reuse >= 0.0) out += " reuse=" + shortNumber(reuse);
    return out;
  }
  static std::string shortNumber(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    return buf;
  }
};

SceneWorld sceneWorld(const Case& c, const PackageOptions& package = PackageOptions{}) {
  SceneParams params;
  params.entities = c.bodies;
  WorldConfig config;
  if (package.iterations > 0) config.response.iterations = package.iterations;
  if (package.reuse >= 0.0) config.response.reuse_tolerance = package.reuse;
  if (!package.solver.empty()) config.response.solver = parseSolverKind(package.solver);
  return makeSceneWorld(c.kind, params, config);
}

void timeTick(Run& run, double wall0, double cpu0) {
  run.wall.push_back(stc_bench::wallSeconds() - wall0);
  run.cpu.push_back(stc_bench::threadCpuSeconds() - cpu0);
}

// One World of a scene, ticked and timed a tick at a time (so that several
// can take turns).
class PackageRun {
 public:
  PackageRun(const Case& c, int settle_ticks, const PackageOptions& package, bool cpu_phases)
      : scene_(sceneWorld(c, package)), check_(scene_.spec.bounds, scene_.spec.dt) {
    World& world = scene_.world;
    if (cpu_phases) world.setClock(stc_bench::threadCpuSeconds);
    for (int t = 0; t < settle_ticks; ++t) world.step(scene_.spec.dt, Budget::unlimited());
    for (EntityId id : scene_.spec.movers) dense_.push_back(*world.indexOf(id));
    positions_.resize(dense_.size());
    velocities_.resize(dense_.size());
    run_.engine = package.label();
    run_.cpu_phases = cpu_phases;
    read();
    check_.start(positions_);
  }
  void tick() {
    World& world = scene_.world;
    const double wall0 = stc_bench::wallSeconds(), cpu0 = stc_bench::threadCpuSeconds();
    const TickReport r = world.step(scene_.spec.dt, Budget::unlimited());
    timeTick(run_, wall0, cpu0);
    run_.integrate.push_back(r.phases.integrate_s);
    run_.broad.push_back(r.phases.broad_s);
    run_.sweep.push_back(r.phases.sweep_s);
    run_.narrow.push_back(r.phases.narrow_s);
    run_.building.push_back(r.phases.contacts_s);
    run_.detection.push_back(r.phases.broad_s + r.phases.sweep_s + r.phases.narrow_s + r.phases.contacts_s);
    run_.solve.push_back(r.phases.response_s - r.phases.contacts_s);
    run_.contacts.push_back(static_cast<double>(r.response.contacts));
    run_.reused.push_back(r.detection.colliding > 0
                              ? static_cast<double>(r.detection.reused) / static_cast<double>(r.detection.colliding)
                              : 0.0);
    run_.sleeping = static_cast<int>(r.bodies.sleeping);
    read();
    check_.tick(positions_, velocities_);
  }
  Run finish() {
    check_.finish(run_);
    return run_;
  }

 private:
  void read() {
    for (std::size_t i = 0; i < dense_.size(); ++i) {
      positions_[i] = scene_.world.bodies()[dense_[i]].pose.position;
      velocities_[i] = scene_.world.bodies()[dense_[i]].linear_velocity;
    }
  }
  SceneWorld scene_;
  MotionCheck check_;
  std::vector<std::size_t> dense_;
  std::vector<Vec3> positions_, velocities_;
  Run run_;
};

Run runPackage(const Case& c, int ticks, int settle_ticks, const PackageOptions& package) {
  PackageRun run(c, settle_ticks, package, false);
  for (int t = 0; t < ticks; ++t) run.tick();
  return run.finish();
}

// One World per package option, ticked in turns of kTurnTicks ticks.
constexpr int kTurnTicks = 10;
std::vector<Run> runPackagesSideBySide(const Case& c, int ticks, int settle_ticks,
                                       const std::vector<PackageOptions>& packages) {
  std::vector<std::unique_ptr<PackageRun>> runs;
  for (const PackageOptions& p : packages) runs.push_back(std::make_unique<PackageRun>(c, settle_ticks, p, true));
  for (int done = 0; done < ticks; done += kTurnTicks) {
    for (auto& run : runs) {
      for (int t = done; t < std::min(ticks, done + kTurnTicks); ++t) run->tick();
    }
  }
  std::vector<Run> out;
  for (auto& run : runs) out.push_back(run->finish());
  return out;
}

// ---------------------------------------------------------------------------
// Bullet

enum class BulletShape { Compound, Hull, Lean };
const char* toString(BulletShape s) {
  return s == BulletShape::Compound ? "compound" : s == BulletShape::Hull ? "hull" : "lean";
}
constexpr double kLeanMargin = 0.01;  // m: the lean hulls' collision margin

btVector3 bt(const Vec3& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }
Vec3 eig(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }

btScalar combinedRestitution(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getRestitution(), b->getRestitution());
}
btScalar combinedFriction(const btCollisionObject* a, const btCollisionObject* b) {
  return std::sqrt(a->getFriction() * b->getFriction());
}
// Rolling resistance: this package bounds a pair's angular impulse by
// c * r * N (c the larger coefficient, r the rolling radius at the contact);
// Bullet bounds it by its combined coefficient (a length) * N, for rolling and
// for spinning apart. Each movable body carries c * r with r its ball radius
// of gyration, sqrt(5/2 * I / m); static bodies 0; the pair takes the larger.
btScalar combinedRolling(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getRollingFriction(), b->getRollingFriction());
}
btScalar combinedSpinning(const btCollisionObject* a, const btCollisionObject* b) {
  return std::max(a->getSpinningFriction(), b->getSpinningFriction());
}

// Where Bullet's step goes, from its own profile zones (BT_PROFILE, which
// calls the zone hooks whether or not the library was built to profile):
// the wall time inside its collision detection and inside its constraint
// solve, summed over one step. One thread: the hooks keep a stack of the
// zones entered.
class BulletZones {
 public:
  BulletZones() : enter_before_(btGetCurrentEnterProfileZoneFunc()), leave_before_(btGetCurrentLeaveProfileZoneFunc()) {
    depth = 0;
    btSetCustomEnterProfileZoneFunc(&enter);
    btSetCustomLeaveProfileZoneFunc(&leave);
  }
  ~BulletZones() {
    btSetCustomEnterProfileZoneFunc(enter_before_);
    btSetCustomLeaveProfileZoneFunc(leave_before_);
  }
  BulletZones(const BulletZones&) = delete;
  BulletZones& operator=(const BulletZones&) = delete;
  static void startStep() { detection_s = solve_s = 0.0; }
  static double detection_s, solve_s;

 private:
  enum Kind { kOther, kDetection, kSolve };
  struct Open {
    Kind kind;
    double since;
  };
  static constexpr int kDepth = 64;
  static void enter(const char* name) {
    Kind kind = kOther;
    if (std::strcmp(name, "performDiscreteCollisionDetection") == 0) kind = kDetection;
    if (std::strcmp(name, "solveConstraints") == 0) kind = kSolve;
    if (depth < kDepth) open[depth] = {kind, kind == kOther ? 0.0 : stc_bench::wallSeconds()};
    ++depth;
  }
  static void leave() {
    if (depth == 0) return;
    --depth;
    if (depth >= kDepth || open[depth].kind == kOther) return;
    (open[depth].kind == kDetection ? detection_s : solve_s) += stc_bench::wallSeconds() - open[depth].since;
  }
  btEnterProfileZoneFunc* enter_before_;
  btLeaveProfileZoneFunc* leave_before_;
  static Open open[kDepth];
  static int depth;
};
double BulletZones::detection_s = 0.0, BulletZones::solve_s = 0.0;
BulletZones::Open BulletZones::open[BulletZones::kDepth];
int BulletZones::depth = 0;

// One voxel shape as Bullet sees it: Bullet wants the body frame on the
// principal axes of inertia, so points are taken from this package's body
// frame (centre of mass, grid axes) by principal^T.
struct BulletBodyShape {
  btCollisionShape* shape = nullptr;
  Mat3 principal = Mat3::Identity();  // columns: principal axes in the body frame
  Vec3 moments = Vec3::Zero();        // principal moments per kg
};

class BulletScene {
 public:
  BulletScene(const World& world, const SceneSpec& spec, BulletShape kind) : kind_(kind) {
    gCalculateCombinedRestitutionCallback = &combinedRestitution;
    gCalculateCombinedFrictionCallback = &combinedFriction;
    gCalculateCombinedRollingFrictionCallback = &combinedRolling;
    gCalculateCombinedSpinningFrictionCallback = &combinedSpinning;
    world_.setGravity(bt(spec.gravity));
    for (std::size_t i = 0; i < world.entityCount(); ++i) add(world, i);
    for (EntityId id : spec.movers) movers_.push_back(bodies_[*world.indexOf(id)].get());
  }
  // What Bullet got for each shape, one line each: "<shape>: <what>".
  const std::vector<std::string>& shapeNotes() const { return notes_; }
  ~BulletScene() {
    for (auto& body : bodies_) world_.removeRigidBody(body.get());
  }
  void step(double dt) { world_.stepSimulation(btScalar(dt), 0); }
  void read(std::vector<Vec3>& positions, std::vector<Vec3>& velocities) const {
    positions.resize(movers_.size());
    velocities.resize(movers_.size());
    for (std::size_t i = 0; i < movers_.size(); ++i) {
      positions[i] = eig(movers_[i]->getWorldTransform().getOrigin());
      velocities[i] = eig(movers_[i]->getLinearVelocity());
    }
  }
  int sleeping() const {
    int n = 0;
    for (const btRigidBody* b : movers_) n += b->getActivationState() == ISLAND_SLEEPING;
    return n;
  }

 private:
  void add(const World& world, std::size_t index) {
    const BodyState& state = world.bodies()[index];
    const BulletBodyShape& s = shapeOf(world, world.bodyShapes()[index]);
    const double mass = state.is_static ? 0.0 : 1.0 / state.inv_mass;
    btRigidBody::btRigidBodyConstructionInfo info(btScalar(mass), nullptr, s.shape,
                                                  bt(mass * s.moments));
    const Quat q(state.pose.orientation.toRotationMatrix() * s.principal);
    info.m_startWorldTransform =
        btTransform(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
                    bt(state.pose.position));
    info.m_restitution = btScalar(state.material.restitution);
    info.m_friction = btScalar(state.material.friction);
    if (!state.is_static && state.material.rolling_resistance > 0.0) {
      const double radius = std::sqrt(2.5 * s.moments.mean());
      info.m_rollingFriction = btScalar(state.material.rolling_resistance * radius);
      info.m_spinningFriction = info.m_rollingFriction;
    }
    bodies_.push_back(std::make_unique<btRigidBody>(info));
    btRigidBody* body = bodies_.back().get();
    body->setLinearVelocity(bt(state.linear_velocity));
    body->setAngularVelocity(bt(state.angular_velocity));
    world_.addRigidBody(body);
  }

  const BulletBodyShape& shapeOf(const World& world, ShapeId id) {
    auto found = shapes_.find(id);
    if (found != shapes_.end()) return found->second;
    const ShapeInfo& info = world.shape(id);
    BulletBodyShape s;
    const Mat3 inertia = info.unit_mass.inertia / info.unit_mass.mass;  // per kg
    Eigen::SelfAdjointEigenSolver<Mat3> eigen(inertia);
    s.principal = eigen.eigenvectors();
    if (s.principal.determinant() < 0.0) s.principal.col(2) *= -1.0;
    s.moments = eigen.eigenvalues();
    const VoxelShape& v = info.voxels;
    const Vec3 half = 0.5 * v.extent();
    char note[160];
    if (kind_ == BulletShape::Compound) {
      s.shape = leafCompound(info, s.principal);
      std::snprintf(note, sizeof note, "%d leaf spheres", static_cast<btCompoundShape*>(s.shape)->getNumChildShapes());
    } else if (kind_ == BulletShape::Lean && v.occupiedCount() == static_cast<std::int64_t>(v.nx()) * v.ny() * v.nz() &&
               (half - info.body_origin).norm() <= 1e-9 * half.norm()) {
      // A full box, centred on its centre of mass: its grid axes are principal.
      s.principal = Mat3::Identity();
      s.moments = inertia.diagonal();
      auto* box = new btBoxShape(bt(half));
      s.shape = own(box);
      std::snprintf(note, sizeof note, "btBoxShape %.3f x %.3f x %.3f m, margin %.3f m (inside the box)",
                    2.0 * half.x(), 2.0 * half.y(), 2.0 * half.z(), static_cast<double>(box->getMargin()));
    } else {
      auto* hull = static_cast<btConvexHullShape*>(kind_ == BulletShape::Hull ? voxelHull(info, s.principal)
                                                                              : leanHull(info, s.principal));
      s.shape = hull;
      std::snprintf(note, sizeof note, "btConvexHullShape %d vertices, margin %.3f m", hull->getNumPoints(),
                    static_cast<double>(hull->getMargin()));
    }
    char line[256];
    std::snprintf(line, sizeof line, "%s (%d x %d x %d voxels of %.3f m, %lld occupied): %s", info.key.c_str(),
                  v.nx(), v.ny(), v.nz(), v.voxelSize(), static_cast<long long>(v.occupiedCount()), note);
    notes_.push_back(line);
    return shapes_.emplace(id, s).first->second;
  }

  btCollisionShape* own(btCollisionShape* shape) {
    owned_.emplace_back(shape);
    return shape;
  }

  btCollisionShape* leafCompound(const ShapeInfo& info, const Mat3& principal) {
    auto* compound = new btCompoundShape(true);
    own(compound);
    const auto& nodes = info.tree.nodes();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (nodes[i].child_count != 0) continue;
      btTransform at;
      at.setIdentity();
      at.setOrigin(bt(principal.transpose() * nodes[i].centre));
      compound->addChildShape(at, own(new btSphereShape(btScalar(nodes[i].radius))));
    }
    return compound;
  }

  // The corners of the surface voxels, in Bullet's body frame, x y z each.
  static std::vector<double> surfaceCorners(const ShapeInfo& info, const Mat3& principal) {
    const VoxelShape& v = info.voxels;
    std::vector<double> corners;
    for (int k = 0; k < v.nz(); ++k) {
      for (int j = 0; j < v.ny(); ++j) {
        for (int i = 0; i < v.nx(); ++i) {
          if (!v.isSurfaceVoxel(i, j, k)) continue;  // inner corners are inside the hull
          for (int c = 0; c < 8; ++c) {
            const Vec3 grid(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
            const Vec3 p = principal.transpose() * (grid * v.voxelSize() - info.body_origin);
            corners.insert(corners.end(), {p.x(), p.y(), p.z()});
          }
        }
      }
    }
    return corners;
  }

  btCollisionShape* voxelHull(const ShapeInfo& info, const Mat3& principal) {
    const std::vector<double> corners = surfaceCorners(info, principal);
    // Faces moved in by Bullet's default margin (at most a quarter of the
    // hull's inner radius); the margin puts them back.
    btConvexHullComputer computer;
    const btScalar margin = computer.compute(corners.data(), 3 * static_cast<int>(sizeof(double)),
                                             static_cast<int>(corners.size() / 3), btScalar(0.04),
                                             btScalar(0.25));
    auto* hull = new btConvexHullShape();
    own(hull);
    hull->setMargin(margin);
    for (int i = 0; i < computer.vertices.size(); ++i) hull->addPoint(computer.vertices[i], false);
    hull->recalcLocalAabb();
    return hull;
  }

  // Every surface corner, then optimizeConvexHull(): the hull's own vertices
  // alone (collinear and coplanar corners dropped), with a 1 cm margin.
  btCollisionShape* leanHull(const ShapeInfo& info, const Mat3& principal) {
    const std::vector<double> corners = surfaceCorners(info, principal);
    auto* hull = new btConvexHullShape();
    own(hull);
    for (std::size_t i = 0; i < corners.size(); i += 3) {
      hull->addPoint(btVector3(btScalar(corners[i]), btScalar(corners[i + 1]), btScalar(corners[i + 2])), false);
    }
    hull->optimizeConvexHull();
    hull->setMargin(btScalar(kLeanMargin));
    hull->recalcLocalAabb();
    return hull;
  }

  BulletShape kind_;
  btDefaultCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_{&config_};
  btDbvtBroadphase broad_phase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_{&dispatcher_, &broad_phase_, &solver_, &config_};
  std::vector<std::unique_ptr<btCollisionShape>> owned_;
  std::map<ShapeId, BulletBodyShape> shapes_;
  std::vector<std::string> notes_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;  // dense order of the World
  std::vector<btRigidBody*> movers_;
};

Run runBullet(const Case& c, int ticks, int settle_ticks, BulletShape kind) {
  SceneSpec spec;
  std::unique_ptr<BulletScene> scene;
  {
    SceneWorld built = sceneWorld(c);
    spec = built.spec;
    scene = std::make_unique<BulletScene>(built.world, spec, kind);
  }
  for (const std::string& note : scene->shapeNotes()) std::printf("  Bullet %s: %s\n", toString(kind), note.c_str());
  for (int t = 0; t < settle_ticks; ++t) scene->step(spec.dt);
  Run run;
  run.engine = std::string("Bullet ") + toString(kind);
  MotionCheck check(spec.bounds, spec.dt);
  std::vector<Vec3> positions, velocities;
  scene->read(positions, velocities);
  check.start(positions);
  const BulletZones zones;
  for (int t = 0; t < ticks; ++t) {
    BulletZones::startStep();
    const double wall0 = stc_bench::wallSeconds(), cpu0 = stc_bench::threadCpuSeconds();
    scene->step(spec.dt);
    timeTick(run, wall0, cpu0);
    run.detection.push_back(BulletZones::detection_s);
    run.solve.push_back(BulletZones::solve_s);
    run.rest.push_back(run.wall.back() - BulletZones::detection_s - BulletZones::solve_s);
    scene->read(positions, velocities);
    check.tick(positions, velocities);
  }
  check.finish(run);
  run.sleeping = scene->sleeping();
  return run;
}

// ---------------------------------------------------------------------------
// Report

double loadAverage() {
  double load[1] = {NAN};
  return getloadavg(load, 1) == 1 ? load[0] : NAN;
}

std::string label(const Case& c) { return std::string(toString(c.kind)) + " " + std::to_string(c.bodies); }

std::string runRow(const Case& c, const Run& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "| %s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.3f | %.3f | %.3f | %d / %d | %s |\n",
                label(c).c_str(), r.engine.c_str(), 1e3 * percentile(r.cpu, 0.5),
                1e3 * percentile(r.cpu, 0.99), 1e3 * maxOf(r.cpu), 1e3 * percentile(r.wall, 0.5),
                1e3 * percentile(r.wall, 0.99), 1e3 * maxOf(r.wall), r.stored_speed, r.moved_speed,
                r.final_speed, r.out_end, r.out_ever,
                r.sleeping < 0 ? "-" : std::to_string(r.sleeping).c_str());
  return buf;
}

std::string phaseCell(const std::vector<double>& v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.2f / %.2f", 1e3 * percentile(v, 0.5), 1e3 * meanOf(v));
  return b;
}

std::string phaseRow(const Case& c, const Run& r) {
  char buf[512];
  const std::string scene = r.cpu_phases ? label(c) + ", " + r.engine : label(c);
  std::snprintf(buf, sizeof buf, "| %s | %s | %s | %s | %s | %s | %s | %s | %.0f |\n", scene.c_str(),
                phaseCell(r.integrate).c_str(), phaseCell(r.broad).c_str(), phaseCell(r.sweep).c_str(),
                phaseCell(r.narrow).c_str(), phaseCell(r.building).c_str(), phaseCell(r.solve).c_str(),
                phaseCell(r.cpu_phases ? r.cpu : r.wall).c_str(), percentile(r.contacts, 0.5));
  return buf;
}

std::string sideBySideRow(const Case& c, const Run& r, const PackageOptions& package) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "| %s | %s | %s | %s | %s | %s | %.0f %% | %.0f |\n", label(c).c_str(),
                package.label().c_str(),
                phaseCell(r.cpu).c_str(), phaseCell(r.narrow).c_str(), phaseCell(r.building).c_str(),
                phaseCell(r.solve).c_str(), 100.0 * meanOf(r.reused), percentile(r.contacts, 0.5));
  return buf;
}

// Bullet's split beside this package's: its collision detection against this
// package's broad phase, sweep, narrow phase and contacts; solve against solve.
std::string bulletPhaseRow(const Case& c, const Run& ours, const Run& theirs) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "| %s | %s | %s | %s | %s | %s | %s | %s |\n", label(c).c_str(),
                theirs.engine.c_str(), phaseCell(theirs.detection).c_str(), phaseCell(theirs.solve).c_str(),
                phaseCell(theirs.rest).c_str(), phaseCell(theirs.wall).c_str(),
                ours.wall.empty() ? "-" : phaseCell(ours.detection).c_str(),
                ours.wall.empty() ? "-" : phaseCell(ours.solve).c_str());
  return buf;
}

struct Options {
  double seconds = 10.0;
  double settle = 0.0;
  bool bullet_only = false;
  PackageOptions package;
  // --reuse or --solver with several values: one World each (every pair of them), in turns
  std::vector<PackageOptions> side_by_side;
  std::vector<Case> cases;
  std::vector<BulletShape> variants{BulletShape::Compound, BulletShape::Hull, BulletShape::Lean};
  std::string markdown;
};

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  std::string scenes;
  bool smoke = false;
  std::vector<double> reuses;
  std::vector<std::string> solvers;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string a = args.flag();
    if (a == "--seconds") {
      o.seconds = std::stod(args.required());
      if (!(o.seconds > 0.0)) throw InputError("--seconds", "must be > 0");
    } else if (a == "--settle") {
      o.settle = std::stod(args.required());
      if (!(o.settle >= 0.0)) throw InputError("--settle", "must be >= 0");
    } else if (a == "--scenes") {
      scenes = args.required();
    } else if (a == "--variants") {  // may be empty: no Bullet run
      o.variants.clear();
      for (const std::string& v : splitList(args.value())) {
        if (v == "compound") o.variants.push_back(BulletShape::Compound);
        else if (v == "hull") o.variants.push_back(BulletShape::Hull);
        else if (v == "lean") o.variants.push_back(BulletShape::Lean);
        else throw InputError("--variants", "unknown value '" + v + "' (expected compound, hull, lean)");
      }
    } else if (a == "--smoke") {
      smoke = true;
      o.seconds = 0.05;
      o.settle = 0.0;
    } else if (a == "--bullet-only") {
      o.bullet_only = true;
    } else if (a == "--iterations") {
      o.package.iterations = std::stoi(args.required());
      if (o.package.iterations < 1) throw InputError("--iterations", "must be >= 1");
    } else if (a == "--solver") {
      solvers = splitList(args.required());
      for (const std::string& v : solvers) parseSolverKind(v);  // throws InputError("solver") on an unknown name
      if (solvers.empty()) throw InputError("--solver", "names no value");
    } else if (a == "--reuse") {
      reuses.clear();
      for (const std::string& v : splitList(args.required())) {
        const double reuse = std::stod(v);
        if (!(reuse >= 0.0 && reuse <= 1.0)) throw InputError("--reuse", "must be in [0, 1]");
        reuses.push_back(reuse);
      }
      if (reuses.empty()) throw InputError("--reuse", "names no value");
    } else if (a == "--markdown") {
      o.markdown = args.required();
    } else {
      throw InputError(a, "unknown argument");
    }
  }
  if (!reuses.empty()) o.package.reuse = reuses.front();
  if (!solvers.empty()) o.package.solver = solvers.front();
  if (reuses.size() > 1 || solvers.size() > 1) {
    if (reuses.empty()) reuses.push_back(o.package.reuse);
    if (solvers.empty()) solvers.push_back(o.package.solver);
    for (const double reuse : reuses) {
      for (const std::string& solver : solvers) {
        PackageOptions p = o.package;
        p.reuse = reuse;
        p.solver = solver;
        o.side_by_side.push_back(p);
      }
    }
  }
  o.cases = scenes.empty() ? kDefaultCases : stc_bench::parseSceneCases(scenes, kDefaultCases);
  if (smoke) {
    for (Case& c : o.cases) c.bodies = std::min(c.bodies, 100);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!stc_bench::parseFlags("bench_bullet_compare", parse, argc, argv, opt)) return 2;
  const int ticks = static_cast<int>(std::lround(opt.seconds * 60.0));
  const int settle_ticks = static_cast<int>(std::lround(opt.settle * 60.0));
  std::string runs_md =
      "| scene | engine | CPU p50 | CPU p99 | CPU max | wall p50 | wall p99 | wall max | "
      "stored speed | \\|dx\\|/dt | final speed | out of bounds (end / ever) | asleep |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::string phases_md =
      "| scene | integrate | broad | sweep | narrow | contacts | solve | whole tick | contacts p50 |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  std::string bullet_phases_md =
      "| scene | engine | collision detection | solve | the rest | whole tick | "
      "this package's detection (broad + sweep + narrow + contacts) | this package's solve |\n"
      "|---|---|---|---|---|---|---|---|\n";
  std::string summary;
  std::printf("# bench_bullet_compare: %.1f s simulated per run (%d ticks at 60 Hz) after %.1f s untimed, load %.2f\n",
              opt.seconds, ticks, opt.settle, loadAverage());
  std::printf("Bullet variants: compound = btCompoundShape of the leaf spheres; hull = btConvexHullShape of the "
              "surface-voxel corners, faces moved in by Bullet's default margin; lean = full voxel boxes as "
              "btBoxShape, other shapes as optimizeConvexHull() hulls of the surface-voxel corners, margin %.3f m\n",
              kLeanMargin);
  std::string side_md =
      "| scene | this package | whole tick | narrow phase | contacts | solve | colliding pairs carried over "
      "| contacts a tick |\n"
      "|---|---|---|---|---|---|---|---|\n";
  for (const Case& c : opt.cases) {
    std::printf("## %s (load %.2f)\n", label(c).c_str(), loadAverage());
    std::fflush(stdout);
    std::string rows;
    Run ours;
    if (!opt.bullet_only && !opt.side_by_side.empty()) {
      const std::vector<Run> side = runPackagesSideBySide(c, ticks, settle_ticks, opt.side_by_side);
      for (std::size_t k = 0; k < side.size(); ++k) {
        rows += runRow(c, side[k]);
        phases_md += phaseRow(c, side[k]);
        side_md += sideBySideRow(c, side[k], opt.side_by_side[k]);
        std::printf("side by side: %s", sideBySideRow(c, side[k], opt.side_by_side[k]).c_str());
      }
      ours = side.front();
    } else if (!opt.bullet_only) {
      ours = runPackage(c, ticks, settle_ticks, opt.package);
      rows = runRow(c, ours);
    }
    std::printf("%s", rows.c_str());
    std::fflush(stdout);
    double best = NAN;
    std::string best_variant = "none";
    for (BulletShape v : opt.variants) {
      const Run theirs = runBullet(c, ticks, settle_ticks, v);
      const std::string row = runRow(c, theirs);
      std::printf("%s", row.c_str());
      std::fflush(stdout);
      rows += row;
      bullet_phases_md += bulletPhaseRow(c, ours, theirs);
      const double p50 = percentile(theirs.cpu, 0.5);
      if (!(best <= p50)) {
        best = p50;
        best_variant = toString(v);
      }
    }
    runs_md += rows;
    if (!opt.bullet_only && opt.side_by_side.empty()) {
      phases_md += phaseRow(c, ours);
      std::printf("phases p50 / mean ms: %s", phaseRow(c, ours).c_str());
    }
    char buf[256];
    const double p50 = percentile(ours.cpu, 0.5);
    std::snprintf(buf, sizeof buf,
                  "SUMMARY scene=%s bodies=%d p50_ms=%.3f p99_ms=%.3f bullet_best_p50_ms=%.3f "
                  "bullet_best=%s ratio_p50=%.3f%s\n",
                  toString(c.kind), c.bodies, 1e3 * p50, 1e3 * percentile(ours.cpu, 0.99), 1e3 * best,
                  best_variant.c_str(), p50 / best, opt.package.summary().c_str());
    summary += buf;
  }
  std::string md;
  char head[256];
  std::snprintf(head, sizeof head,
                "%.1f s simulated per run (%d ticks, dt = 1/60 s) after %.1f s untimed. Times in ms per "
                "tick; speeds in m/s, means over movers and ticks.\n\n",
                opt.seconds, ticks, opt.settle);
  md = std::string(head) + runs_md +
       (opt.side_by_side.empty() ? "\nThis package's phases, ms per tick (p50 / mean, wall time):\n\n"
                                  : "\nThis package's phases, ms per tick (p50 / mean, thread-CPU):\n\n") +
       phases_md +
       "\nBullet's phases (its profile zones), ms per tick (p50 / mean, wall time):\n\n" + bullet_phases_md;
  if (!opt.side_by_side.empty()) {
    md += "\nSide by side (one World per setting, in turns of " + std::to_string(kTurnTicks) +
          " ticks): thread-CPU ms per tick, p50 / mean; the share of colliding pairs carried over, mean over the "
          "ticks:\n\n" + side_md;
  }
  std::printf("\n%s\nload at the end %.2f\n%s", md.c_str(), loadAverage(), summary.c_str());
  if (!opt.markdown.empty()) std::ofstream(opt.markdown) << md << "\n```\n" << summary << "```\n";
  return 0;
}
