// Continuous collision (issue 9, item 1): on the built-in scenes, does each
// body move as fast as its stored velocity says, and what does the swept test
// cost? Per scene, dt = 1/60 s, World defaults, unlimited budget: mean stored
// speed (the velocity a tick moves with) against mean |dx|/dt over movable
// bodies and ticks; mean ms per tick of each phase; fast bodies, pairs
// swept, leaf box pairs tested and bodies held back per tick.
//
// Usage: bench_continuous [--seconds S] [--smoke] [SCENE[:N] ...]
//   --smoke: 3 ticks of small scenes, that the bench runs (scripts/bench_smoke.sh)
//   default: packed_box:500 bouncing_box:100 rockfall:1000 corner_drift:500, 10 s
//   e.g.     bench_continuous --seconds 2 rockfall:1000
#include "physics.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using namespace stc;

double threadCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void runScene(SceneKind kind, int count, double seconds) {  // count 0: the scene default
  SceneParams params;
  params.entities = count;
  SceneWorld scene = makeSceneWorld(kind, params);
  World& world = scene.world;
  const SceneSpec& spec = scene.spec;
  const double dt = spec.dt;
  const int steps = static_cast<int>(seconds / dt + 0.5);
  double stored = 0.0, real = 0.0;
  long samples = 0;
  double integrate = 0.0, sweep = 0.0, broad = 0.0, narrow = 0.0, response = 0.0, cpu = 0.0;
  double fast = 0.0, pairs = 0.0, leaves = 0.0, clamped = 0.0;
  std::vector<Vec3> before;
  std::vector<double> speed;
  for (int s = 0; s < steps; ++s) {
    const std::vector<BodyState>& b = world.bodies();
    before.resize(b.size());
    speed.resize(b.size());
    for (std::size_t i = 0; i < b.size(); ++i) {
      before[i] = b[i].pose.position;
      speed[i] = b[i].linear_velocity.norm();
    }
    const double c0 = threadCpuSeconds();
    const TickReport r = world.step(dt, Budget::unlimited());
    cpu += threadCpuSeconds() - c0;
    integrate += r.phases.integrate_s;
    sweep += r.phases.sweep_s;
    broad += r.phases.broad_s;
    narrow += r.phases.narrow_s;
    response += r.phases.response_s;
    const SweepStats& st = physicsReport(world).sweep;
    fast += static_cast<double>(st.fast_bodies);
    pairs += static_cast<double>(st.pairs);
    leaves += static_cast<double>(st.leaf_tests);
    clamped += static_cast<double>(st.clamped);
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (b[i].is_static) continue;
      stored += speed[i];
      real += (b[i].pose.position - before[i]).norm() / dt;
      ++samples;
    }
  }
  const double n = steps > 0 ? steps : 1;
  const double ms = 1e3 / n;
  std::printf("| %s | %d | %.3f | %.3f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.0f | %.2f |\n",
              toString(kind), static_cast<int>(spec.movers.size()), stored / static_cast<double>(samples), real / static_cast<double>(samples),
              integrate * ms, sweep * ms, broad * ms, narrow * ms, response * ms, cpu * ms, fast / n, pairs / n,
              leaves / n, clamped / n);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  bool smoke = false;
  std::vector<std::pair<SceneKind, int>> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
      continue;
    }
    if (a == "--smoke") {
      smoke = true;
      seconds = 0.05;
      continue;
    }
    const std::size_t colon = a.find(':');
    const SceneKind kind = parseScene(a.substr(0, colon));
    scenes.emplace_back(kind, colon == std::string::npos ? 0 : std::atoi(a.c_str() + colon + 1));
  }
  if (scenes.empty()) {
    const int n = smoke ? 10 : 100;  // the bodies of the smallest scene
    scenes = {{SceneKind::PackedBox, 5 * n}, {SceneKind::BouncingBox, n}, {SceneKind::Rockfall, 10 * n},
              {SceneKind::CornerDrift, 5 * n}};
  }
  std::printf("%.0f s at dt = 1/60 s, unlimited budget. Speeds in m/s (stored: the velocity a tick moves with; "
              "real: |dx|/dt), phase times mean wall ms per tick, tick CPU = thread CPU ms per tick; sweep "
              "counts mean per tick.\n\n",
              seconds);
  std::printf("| scene | bodies | stored speed | real speed | integrate | sweep | broad | narrow | response | tick CPU | fast | pairs swept | leaf tests | held back |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [kind, count] : scenes) runScene(kind, count, seconds);
  return 0;
}
