// Load (issue 5, items 6 and 7): what the node's World costs as it fills up,
// and what a scene saves by leaving out what it does not need. Core only: the
// node's ROS costs (markers, tf) are measured on the running node by
// bench/ros_publish_cost.py.
//
// 1. Bursts: rocks rain onto a tiled floor in bursts of 250 while the World
//    ticks at dt = 1/60 s with the node's defaults (8 ms wall-clock narrow
//    budget, priority queues, policy accept, response on, gravity), up to
//    5,000. Per band of 1,000 entities: achieved tick rate (ticks per second
//    of wall time, spawning included), per-phase times, spawn cost.
// 2. Memory per entity: resident set growth (/proc/self/statm) from the
//    empty World to 5,000 entities after ticking, each in a fresh child
//    process; side by side with FCL holding the same entities (shared BVH
//    meshes, one CollisionObject each, a DynamicAABBTree manager).
// 3. Leave out what a scene does not need: 2,000 rocks, each feature present
//    and absent, everything else equal (same seed): gaze, gravity, rotation,
//    all-static, all-sphere. Mean phase times per tick (best of 3 runs, runs
//    interleaved, since the machine may be shared) and thread CPU time.
//
// Usage: bench_load [--quick|--smoke] [--markdown FILE]   (--smoke: that the bench runs, scripts/bench_smoke.sh)
#include "fcl_mesh.hpp"
#include "physics.hpp"
#include "sphere_tree_collision/world.hpp"
#include "tick_clock.hpp"
#include "world_access.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision_object.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace stc;
using Clock = std::chrono::steady_clock;

constexpr double kDt = 1.0 / 60.0;
constexpr int kRockSeeds = 4;
constexpr double kRockSize = 0.4;  // m: largest extent (8 voxels of 5 cm)

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

using stc_bench::threadCpuSeconds;

double residentBytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE));
}

// Runs `f` in a child process (a fresh heap, so resident-set growth is its
// own) and returns the doubles it writes.
std::vector<double> inChild(const std::function<std::vector<double>()>& f, std::size_t count) {
  int fds[2];
  if (pipe(fds) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const std::vector<double> out = f();
    const ssize_t written = write(fds[1], out.data(), out.size() * sizeof(double));
    _exit(written == static_cast<ssize_t>(out.size() * sizeof(double)) ? 0 : 1);
  }
  close(fds[1]);
  std::vector<double> out(count, NAN);
  const ssize_t got = read(fds[0], out.data(), count * sizeof(double));
  close(fds[0]);
  waitpid(pid, nullptr, 0);
  if (got != static_cast<ssize_t>(count * sizeof(double))) return std::vector<double>(count, NAN);
  return out;
}

// ---------------------------------------------------------------------------
// Shapes and entities

struct Shapes {
  std::vector<ShapeId> rocks;
  ShapeId sphere = 0;
  ShapeId floor_tile = 0;
};

Shapes addShapes(World& world) {
  Shapes s;
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = kRockSize / 8;
  for (int seed = 1; seed <= kRockSeeds; ++seed) {
    p.seed = static_cast<std::uint32_t>(seed);
    s.rocks.push_back(world.addShape("rock" + std::to_string(seed), makePreset("rock", p)));
  }
  s.sphere = world.addShape("sphere", makePreset("sphere", p));
  PresetParams tile;
  tile.resolution = 8;
  tile.voxel_size = 0.5;  // 4 m x 4 m x 0.5 m
  s.floor_tile = world.addShape("floor_tile", makePreset("plate", tile));
  return s;
}

Quat randomOrientation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Quat q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q;
}

// A floor of tiles x tiles plates of 4 m, top face at z = 0, centred on the origin.
void addFloor(World& world, const Shapes& shapes, int tiles) {
  const double thickness = world.shape(shapes.floor_tile).voxels.nz() * 0.5;
  for (int i = 0; i < tiles; ++i) {
    for (int j = 0; j < tiles; ++j) {
      EntitySpec e;
      e.shape = shapes.floor_tile;
      e.pose.position = Vec3(4.0 * (i - 0.5 * (tiles - 1)), 4.0 * (j - 0.5 * (tiles - 1)), -0.5 * thickness);
      e.is_static = true;
      world.addEntity(e);
    }
  }
}

// ---------------------------------------------------------------------------
// 1 + 2. Bursts of rocks onto a floor while ticking

constexpr int kBurst = 250;
constexpr int kTicksBetweenBursts = 12;  // 0.2 s
constexpr int kFloorTiles = 6;           // 24 m x 24 m
constexpr double kCell = 1.2;            // m: spawn cells, 20 x 20 over the floor

struct BandStats {
  int entities_from = 0, entities_to = 0;
  int ticks = 0;
  double wall = 0, spawn = 0, cpu = 0;  // s
  int spawned = 0;
  double integrate = 0, broad = 0, narrow = 0, response = 0, total = 0;  // s, summed
  double broad_pairs = 0, unresolved = 0, contacts = 0, fast_bodies = 0;
  int interrupted = 0;
};

WorldConfig nodeDefaults() {
  WorldConfig c;
  c.gravity = Vec3(0, 0, -9.81);
  c.scheduler.kind = SchedulerKind::PriorityQueues;
  c.unresolved_policy = UnresolvedPolicy::Accept;
  return c;
}

// Adds one burst of rocks in random free cells 3..4 m above the floor.
void spawnBurst(World& world, const Shapes& shapes, std::mt19937& rng, int count) {
  const int cells = static_cast<int>(4.0 * kFloorTiles / kCell);
  std::vector<int> order(cells * cells);
  for (int i = 0; i < cells * cells; ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), height(3.0, 4.0), speed(-0.5, 0.5);
  for (int k = 0; k < count; ++k) {
    const int cell = order[k % order.size()];
    EntitySpec e;
    e.shape = shapes.rocks[k % shapes.rocks.size()];
    e.pose.position = Vec3(kCell * (cell % cells - 0.5 * (cells - 1)) + jitter(rng),
                           kCell * (cell / cells - 0.5 * (cells - 1)) + jitter(rng), height(rng));
    e.pose.orientation = randomOrientation(rng);
    e.linear_velocity = Vec3(speed(rng), speed(rng), speed(rng));
    e.angular_velocity = 2.0 * Vec3(speed(rng), speed(rng), speed(rng));
    world.addEntity(e);
  }
}

struct BurstRun {
  std::vector<BandStats> bands;
  double rss_start = 0, rss_end = 0;  // bytes: empty scene built; end of the run
};

BurstRun runBursts(int max_entities, int settle_ticks, double budget_ms) {
  BurstRun run;
  World world(nodeDefaults());
  const Shapes shapes = addShapes(world);
  addFloor(world, shapes, kFloorTiles);
  const std::size_t floor_count = world.entityCount();
  world.step(kDt, Budget::ofSeconds(budget_ms * 1e-3));
  run.rss_start = residentBytes();
  std::mt19937 rng(7);
  const Budget budget = Budget::ofSeconds(budget_ms * 1e-3);
  std::vector<BandStats>& bands = run.bands;
  auto bandOf = [&](int rocks) -> BandStats& {
    const int from = (rocks / 1000) * 1000;
    if (bands.empty() || bands.back().entities_from != from) {
      bands.push_back(BandStats{});
      bands.back().entities_from = from;
    }
    bands.back().entities_to = rocks;
    return bands.back();
  };
  int tick = 0;
  int settle = 0;
  while (settle < settle_ticks) {
    const int rocks = static_cast<int>(world.entityCount() - floor_count);
    BandStats& band = bandOf(rocks == max_entities ? max_entities : rocks);
    const auto t0 = Clock::now();
    if (tick % kTicksBetweenBursts == 0 && rocks < max_entities) {
      const int n = std::min(kBurst, max_entities - rocks);
      spawnBurst(world, shapes, rng, n);
      band.spawned += n;
      band.spawn += seconds(t0, Clock::now());
    }
    const double cpu0 = threadCpuSeconds();
    const TickReport r = world.step(kDt, budget);
    band.cpu += threadCpuSeconds() - cpu0;
    band.wall += seconds(t0, Clock::now());
    ++band.ticks;
    band.integrate += r.phases.integrate_s;
    band.broad += r.phases.broad_s;
    band.narrow += r.phases.narrow_s;
    band.response += r.phases.response_s;
    band.total += r.phases.total_s;
    band.broad_pairs += static_cast<double>(r.detection.broad_pairs);
    band.unresolved += static_cast<double>(r.detection.unresolved);
    band.contacts += static_cast<double>(r.response.contacts);
    band.fast_bodies += static_cast<double>(physicsReport(world).sweep.fast_bodies);
    band.interrupted += r.detection.interrupted;
    ++tick;
    if (static_cast<int>(world.entityCount() - floor_count) >= max_entities) ++settle;
  }
  run.rss_end = residentBytes();
  return run;
}

// Resident-set growth per rock from the empty World (shapes and floor built)
// to all rocks added, before any tick. [bytes per entity, MB at start, MB at end].
std::vector<double> worldMemory(int entities) {
  World world(nodeDefaults());
  const Shapes shapes = addShapes(world);
  addFloor(world, shapes, kFloorTiles);
  world.step(kDt, Budget::ofSeconds(8e-3));
  const double before = residentBytes();
  std::mt19937 rng(7);
  for (int spawned = 0; spawned < entities; spawned += kBurst) {
    spawnBurst(world, shapes, rng, std::min(kBurst, entities - spawned));
  }
  const double after = residentBytes();
  return {(after - before) / entities, before / 1e6, after / 1e6};
}

// The same rocks held by FCL: one BVH mesh per shape (shared), a CollisionObject
// per entity, registered in a DynamicAABBTree manager. [bytes per entity, MB
// total, MB at start, us per registered object].
std::vector<double> fclMemory(int entities) {
  World shapes_only(nodeDefaults());
  const Shapes shapes = addShapes(shapes_only);
  std::vector<std::shared_ptr<truth::FclMesh>> meshes;
  for (ShapeId id : shapes.rocks) {
    meshes.push_back(truth::makeFclMesh(shapes_only.shape(id).voxels, shapes_only.shape(id).body_origin));
  }
  const double before = residentBytes();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-12.0, 12.0);
  const auto t0 = Clock::now();
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  fcl::DynamicAABBTreeCollisionManagerd manager;
  for (int i = 0; i < entities; ++i) {
    Pose pose;
    pose.position = Vec3(u(rng), u(rng), 0.5 * (u(rng) + 12.0));
    pose.orientation = randomOrientation(rng);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(meshes[i % meshes.size()], truth::toFcl(pose)));
    objects.back()->computeAABB();
    manager.registerObject(objects.back().get());
  }
  manager.setup();
  const double register_s = seconds(t0, Clock::now());
  const double after = residentBytes();
  return {(after - before) / entities, after / 1e6, before / 1e6, 1e6 * register_s / entities};
}

// ---------------------------------------------------------------------------
// 3. Leave out what a scene does not need

struct Variant {
  std::string name;
  bool gaze = false;
  bool gravity = false;
  bool spin = true;
  bool moving = true;
  bool all_static = false;
  bool spheres = false;
  bool dense = true;                       // lattice touching (pairs) or spread (no pairs)
  bool continuous = true;                  // swept test of fast bodies (ResponseOptions)
  std::int64_t sphere_test_budget = -1;    // -1: none
};

struct Cost {
  double integrate = 0, broad = 0, narrow = 0, response = 0, total = 0, overhead = 0, cpu = 0;  // ms per tick
  double broad_pairs = 0, sphere_tests = 0;
  bool perception_used = false;
};

Cost measure(const Variant& v, int entities, int warmup, int ticks) {
  WorldConfig config = nodeDefaults();
  config.gravity = v.gravity ? Vec3(0, 0, -9.81) : Vec3::Zero();
  config.response.continuous = v.continuous;
  World world(config);
  const Shapes shapes = addShapes(world);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(entities))));
  const double spacing = v.dense ? 0.9 * kRockSize : 2.5 * kRockSize;
  for (int i = 0; i < entities; ++i) {
    EntitySpec e;
    e.shape = v.spheres ? shapes.sphere : shapes.rocks[i % shapes.rocks.size()];
    e.pose.position = spacing * Vec3(i % side - 0.5 * (side - 1), (i / side) % side - 0.5 * (side - 1),
                                     i / (side * side) - 0.5 * (side - 1));
    e.pose.orientation = randomOrientation(rng);
    const Vec3 velocity(u(rng), u(rng), u(rng));
    const Vec3 spin(u(rng), u(rng), u(rng));
    if (v.moving) e.linear_velocity = 0.3 * velocity;
    if (v.spin) e.angular_velocity = 2.0 * spin;
    e.is_static = v.all_static;
    world.addEntity(e);
  }
  Camera camera;
  const double reach = spacing * side;
  camera.camera_to_world = opticalLookAt(Vec3(0.0, -1.6 * reach, 0.6 * reach), Vec3::Zero());
  world.perception().setCamera(camera);
  if (v.gaze) world.perception().setFixation(Vec2(0.5 * camera.width, 0.5 * camera.height));
  const Budget budget = v.sphere_test_budget >= 0 ? Budget::ofSphereTests(v.sphere_test_budget) : Budget::unlimited();

  for (int i = 0; i < warmup; ++i) world.step(kDt, budget);
  Cost c;
  for (int i = 0; i < ticks; ++i) {
    const double cpu0 = threadCpuSeconds();
    const TickReport r = world.step(kDt, budget);
    c.cpu += threadCpuSeconds() - cpu0;
    c.integrate += r.phases.integrate_s;
    c.broad += r.phases.broad_s;
    c.narrow += r.phases.narrow_s;
    c.response += r.phases.response_s;
    c.total += r.phases.total_s;
    c.overhead += r.detection.scheduling_overhead_s;
    c.broad_pairs += static_cast<double>(r.detection.broad_pairs);
    c.sphere_tests += static_cast<double>(r.detection.sphere_tests);
    c.perception_used = c.perception_used || r.accuracy.perception_used;
  }
  for (double* x : {&c.integrate, &c.broad, &c.narrow, &c.response, &c.total, &c.overhead, &c.cpu}) {
    *x *= 1e3 / ticks;
  }
  c.broad_pairs /= ticks;
  c.sphere_tests /= ticks;
  return c;
}

// Best of `reps` runs per variant, the variants interleaved.
std::vector<Cost> measureBest(const std::vector<Variant>& variants, int entities, int warmup, int ticks, int reps) {
  std::vector<Cost> best(variants.size());
  for (int r = 0; r < reps; ++r) {
    for (std::size_t i = 0; i < variants.size(); ++i) {
      const Cost c = measure(variants[i], entities, warmup, ticks);
      if (r == 0) {
        best[i] = c;
        continue;
      }
      Cost& b = best[i];  // each time its own minimum: load spikes hit phases at random
      for (auto field : {&Cost::integrate, &Cost::broad, &Cost::narrow, &Cost::response, &Cost::total,
                         &Cost::overhead, &Cost::cpu}) {
        b.*field = std::min(b.*field, c.*field);
      }
    }
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  int entities = 5000;
  int settle_ticks = 60;
  int lean_entities = 2000;
  int lean_ticks = 60;
  int reps = 5;
  std::string markdown;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick") {
      entities = 1000;
      settle_ticks = 10;
      lean_entities = 300;
      lean_ticks = 10;
      reps = 1;
    } else if (a == "--smoke") {
      entities = 2 * kBurst;  // two bursts
      settle_ticks = 3;
      lean_entities = 100;
      lean_ticks = 3;
      reps = 1;
    } else if (a == "--markdown" && i + 1 < argc) {
      markdown = argv[++i];
    } else {
      std::fprintf(stderr, "usage: bench_load [--quick|--smoke] [--markdown FILE]\n");
      return 2;
    }
  }
  std::string md;
  char buf[1024];
  auto add = [&](const char* fmt, auto... args) {
    std::snprintf(buf, sizeof buf, fmt, args...);
    md += buf;
  };

  // 2 first: children forked from a process whose heap is still small, so
  // resident-set growth is each child's own (the bursts then run here).
  std::fprintf(stderr, "memory: %d rocks (World, FCL) ...\n", entities);
  const std::vector<double> wm = inChild([&] { return worldMemory(entities); }, 3);
  const std::vector<double> fm = inChild([&] { return fclMemory(entities); }, 4);

  // 1. Bursts.
  std::fprintf(stderr, "bursts: %d rocks, %d per burst ...\n", entities, kBurst);
  const BurstRun bursts = runBursts(entities, settle_ticks, 8.0);
  const std::vector<BandStats>& bands = bursts.bands;
  add("### Bursts of rocks while ticking\n\n"
      "Rocks (4 seeded shapes, 0.4 m, 8 voxels across) in bursts of %d every %d ticks onto a %dx%d m tiled "
      "floor, dt = 1/60 s, node defaults: 8 ms wall-clock narrow budget, priority queues, policy accept, "
      "response on, gravity. Achieved rate = ticks / wall time, spawning included. Phase times are wall-clock "
      "means per tick in ms (TickReport); tick CPU is the thread CPU time of the tick (lower than the wall "
      "time when the machine is shared); the last row is %d ticks after the last burst.\n\n",
      kBurst, kTicksBetweenBursts, 4 * kFloorTiles, 4 * kFloorTiles, settle_ticks);
  md += "| rocks | ticks | achieved rate (Hz) | integrate | broad | narrow | response | tick total | tick CPU | "
        "broad pairs | unresolved | contacts | fast bodies swept | interrupted | spawn (us / rock) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const BandStats& b : bands) {
    const double t = b.ticks;
    add("| %d-%d | %d | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f | %.0f%% | %s |\n",
        b.entities_from, b.entities_to, b.ticks, b.ticks / b.wall, 1e3 * b.integrate / t, 1e3 * b.broad / t,
        1e3 * b.narrow / t, 1e3 * b.response / t, 1e3 * b.total / t, 1e3 * b.cpu / t, b.broad_pairs / t, b.unresolved / t,
        b.contacts / t, b.fast_bodies / t, 100.0 * b.interrupted / t,
        b.spawned ? std::to_string(static_cast<int>(std::lround(1e6 * b.spawn / b.spawned))).c_str() : "-");
  }

  // 2. Memory (measured above).
  add("\n### Memory per entity\n\n"
      "Resident-set growth (/proc/self/statm) from the empty scene (shapes and floor built) to %d rocks. "
      "World, rocks added: before any tick, in a fresh child process. World, in the pile: at the end of the "
      "bursts run above (pair pools, pair arena, contacts and solver state of %.0f contacts per tick "
      "included). FCL: the same rocks as CollisionObjects sharing one BVH mesh per shape, registered in a "
      "DynamicAABBTree manager (no simulation state), in a fresh child process.\n\n"
      "| holder | bytes per entity | RSS at start (MB) | RSS at end (MB) |\n|---|---|---|---|\n"
      "| stc::World, rocks added | %.0f | %.1f | %.1f |\n| stc::World, in the pile | %.0f | %.1f | %.1f |\n"
      "| FCL objects + manager | %.0f | %.1f | %.1f |\n"
      "\nRatio World (rocks added) / FCL: %.2f. FCL registers an object in %.2f us.\n",
      entities, bands.back().contacts / bands.back().ticks, wm[0], wm[1], wm[2],
      (bursts.rss_end - bursts.rss_start) / entities, bursts.rss_start / 1e6, bursts.rss_end / 1e6, fm[0], fm[2],
      fm[1], wm[0] / fm[0], fm[3]);

  // 3. Leave out.
  std::fprintf(stderr, "leave out: %d rocks, %d ticks x %d runs per variant ...\n", lean_entities, lean_ticks, reps);
  struct Pair {
    const char* feature;
    Variant present, absent;
  };
  const std::int64_t tight = 20000;
  std::vector<Pair> pairs;
  {
    Variant base;
    base.sphere_test_budget = tight;
    Variant g = base;
    g.gaze = true;
    pairs.push_back({"gaze (fixation set; 20k sphere-test budget)", g, base});
  }
  {
    Variant spread;
    spread.dense = false;
    Variant g = spread;
    g.gravity = true;
    pairs.push_back({"gravity (spread out, no contacts)", g, spread});
  }
  {
    Variant spread;
    spread.dense = false;
    spread.continuous = false;
    Variant g = spread;
    g.gravity = true;
    pairs.push_back({"gravity, swept test of fast bodies off", g, spread});
  }
  {
    Variant spread;
    spread.dense = false;
    Variant still = spread;
    still.spin = false;
    pairs.push_back({"rotation (spread out, no contacts)", spread, still});
  }
  {
    Variant dense;
    Variant fixed = dense;
    fixed.all_static = true;
    pairs.push_back({"movement (all dynamic vs all static, packed)", dense, fixed});
  }
  {
    Variant rocks;
    Variant balls = rocks;
    balls.spheres = true;
    pairs.push_back({"non-sphere shapes (rocks vs spheres, packed, no budget)", rocks, balls});
  }
  add("\n### Leave out what a scene does not need\n\n"
      "%d entities on a lattice (packed: 0.9 x their size apart, so neighbours touch; spread: 2.5 x, so "
      "nothing touches), random velocities (0.3 m/s) and spins (2 rad/s), no budget unless said. Each "
      "variant: %d ticks after a warm-up, each time the best of %d interleaved runs; times are ms per "
      "tick (wall per phase; CPU = thread CPU time of the whole tick). \"Saved\" = present - absent.\n\n"
      "| feature | variant | integrate | broad | narrow | of which scheduling | response | tick total | CPU | "
      "broad pairs | sphere tests | perception used |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      lean_entities, lean_ticks, reps);
  for (const Pair& p : pairs) {
    const std::vector<Cost> c = measureBest({p.present, p.absent}, lean_entities, 5, lean_ticks, reps);
    const char* names[2] = {"present", "absent"};
    for (int k = 0; k < 2; ++k) {
      add("| %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.0f | %.0f | %s |\n", k == 0 ? p.feature : "",
          names[k], c[k].integrate, c[k].broad, c[k].narrow, c[k].overhead, c[k].response, c[k].total, c[k].cpu,
          c[k].broad_pairs, c[k].sphere_tests, c[k].perception_used ? "yes" : "no");
    }
    add("| | saved | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | | | |\n", c[0].integrate - c[1].integrate,
        c[0].broad - c[1].broad, c[0].narrow - c[1].narrow, c[0].overhead - c[1].overhead,
        c[0].response - c[1].response, c[0].total - c[1].total, c[0].cpu - c[1].cpu);
  }
  std::printf("%s", md.c_str());
  if (!markdown.empty()) std::ofstream(markdown) << md;
  return 0;
}
