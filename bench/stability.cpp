// Stability report (issue 4, item 6): per stiff or extreme scene, the max
// energy drift, max penetration, max speed, NaN count and steps per second;
// then the solver choices side by side on the scenes that decide between
// them (docs/response.md). Prints markdown tables.
//
//   bench_stability            all scenes, default response options
//   bench_stability --quick    shorter runs
//   bench_stability --smoke    a few ticks of each: that the bench runs, scripts/bench_smoke.sh
#include "stability_scenes.hpp"

#include "dynamics.hpp"

#include <cstdio>
#include <cstring>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace stc;
using namespace stc::stability;

namespace {

struct Row {
  std::string scene;
  std::string outcome;
  Metrics m;
};

void printTable(const std::vector<Row>& rows) {
  std::printf("| scene | outcome | max energy gain | max penetration (voxels) | max speed (m/s) | NaN | steps/s |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|\n");
  for (const Row& r : rows) {
    std::printf("| %s | %s | %.2e | %.3f | %.3g | %zu | %.0f |\n", r.scene.c_str(), r.outcome.c_str(),
                r.m.energy_gain, r.m.max_penetration, r.m.max_speed, r.m.nan_count, r.m.steps_per_second);
  }
}

std::string fmt(const char* format, double a, double b = 0.0) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), format, a, b);
  return buffer;
}

Row stackRow(const std::string& label, Scene scene) {
  const Metrics m = run(scene);
  return {label, fmt("drift %.3f voxel/s after settling", m.drift), m};
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const bool smoke = argc > 1 && std::strcmp(argv[1], "--smoke") == 0;
  const double t = smoke ? 0.01 : quick ? 0.25 : 1.0;  // fraction of the full durations

  std::vector<Row> rows;
  rows.push_back(stackRow("stack of 10 cubes, 10 s", stack(10, 0.05, 1.0 / 60.0, 10.0 * t, 2.0 * t)));

  {
    Scene scene = massRatio(1000.0, 5.0 * t);
    const std::size_t heavy = scene.movers.back();
    const double rest = scene.world->bodies()[heavy].pose.position.z();
    const Metrics m = run(scene);
    const double sink = (rest - scene.world->bodies()[heavy].pose.position.z()) / scene.voxel;
    // Settling may lift it a little: said as a rise (no "-0.000" sunk).
    rows.push_back({"heavy cube on 4 light cubes, 1000:1",
                    fmt(sink >= 0.0 ? "heavy sank %.3f voxels" : "heavy rose %.3f voxels", std::abs(sink)), m});
  }
  {
    Scene scene = fastSphere(100.0, 0.5);
    double lowest = 1e9;
    const std::size_t ball = scene.movers.front();
    const Metrics m = run(scene, [&](const World& w, int) {
      lowest = std::min(lowest, w.bodies()[ball].pose.position.z());
    });
    const bool through = lowest < 0.0;
    rows.push_back({"1-voxel sphere at 100 m/s vs 1-voxel plate",
                    fmt(through ? "TUNNELLED (lowest centre %.3f voxels)" : "no tunnelling (lowest centre %.3f voxels above the plate centre)",
                        lowest / scene.voxel),
                    m});
  }
  {
    Scene scene = spinningRod(100.0, 10.0 * t);
    const std::size_t rod = scene.movers.front();
    const double e0 = kineticEnergy(scene.world->bodies()[rod]);
    double worst = 0.0;
    double min_axis = 1.0;
    const Metrics m = run(scene, [&](const World& w, int) {
      const BodyState& b = w.bodies()[rod];
      worst = std::max(worst, (kineticEnergy(b) - e0) / e0);
      const Vec3 body_w = b.pose.orientation.conjugate() * b.angular_velocity;
      min_axis = std::min(min_axis, body_w.y() / 100.0);
    });
    rows.push_back({"thin rod at 100 rad/s about its intermediate axis",
                    fmt("kinetic energy max rise %.1e; spin axis flips (min w_y/w0 %.2f)", worst, min_axis), m});
  }
  {
    Scene scene = newtonsCradle(5, 2.0);
    const std::vector<BodyState>& b = scene.world->bodies();
    double e0 = 0.0;
    for (const std::size_t i : scene.movers) e0 += kineticEnergy(b[i]);
    const Vec3 p0 = linearMomentum(b);
    const Metrics m = run(scene);
    double e = 0.0;
    std::string speeds;
    for (const std::size_t i : scene.movers) {
      e += kineticEnergy(b[i]);
      speeds += (speeds.empty() ? "" : ", ") + fmt("%.2f", b[i].linear_velocity.x());
    }
    rows.push_back({"Newton's cradle of 5 touching balls, e = 1, 1 m/s",
                    fmt("kinetic energy kept %.4f, momentum change %.1e; final speeds ", e / e0,
                        (linearMomentum(b) - p0).norm() / p0.norm()) + speeds + " m/s",
                    m});
  }
  rows.push_back(stackRow("stack of 10, 1 mm voxels", stack(10, 0.001, 1.0 / 60.0, 10.0 * t, 2.0 * t)));
  rows.push_back(stackRow("stack of 10, 100 m voxels", stack(10, 100.0, 1.0 / 60.0, 10.0 * t, 2.0 * t)));
  rows.push_back(stackRow("stack of 10, dt = 1e-4", stack(10, 0.05, 1e-4, 2.0 * t, 0.5 * t)));
  rows.push_back(stackRow("stack of 10, dt = 0.1", stack(10, 0.05, 0.1, 20.0 * t, 5.0 * t)));
  {
    Scene scene = cornerPile(125, 4, 4.0 * t, Budget::ofSphereTests(0));
    const Metrics m = run(scene);
    rows.push_back({"zero budget (125 rocks, all pairs accepted unresolved)",
                    fmt("final max speed %.3f m/s", m.final_max_speed), m});
  }
  {
    Scene scene = cornerPile(500, 4, 4.0 * t);
    const Metrics m = run(scene);
    rows.push_back({"500 rocks dropped into a corner", fmt("final max speed %.3f m/s", m.final_max_speed), m});
  }
  std::printf("## Stiff and extreme scenes (default ResponseOptions)\n\n");
  printTable(rows);

  // Solver choices: what holds a stack and a heavy body, at what cost.
  struct Choice {
    const char* name;
    std::function<void(ResponseOptions&)> set;
  };
  const std::vector<Choice> choices = {
      {"sequential, warm start, shock propagation (default)", [](ResponseOptions&) {}},
      {"sequential, warm start, no shock propagation", [](ResponseOptions& o) { o.shock_propagation = false; }},
      {"sequential, no warm start, no shock propagation",
       [](ResponseOptions& o) { o.shock_propagation = false; o.warm_starting = false; }},
      {"Jacobi (simultaneous), warm start, shock propagation",
       [](ResponseOptions& o) { o.solver = SolverKind::Jacobi; }},
      {"Jacobi (simultaneous), warm start, no shock propagation",
       [](ResponseOptions& o) { o.solver = SolverKind::Jacobi; o.shock_propagation = false; }},
      {"sequential, paper normals only (no voxel-box faces)", [](ResponseOptions& o) { o.face_normals = false; }},
      {"sequential, 10 iterations", [](ResponseOptions& o) { o.iterations = 10; }},
      {"sequential, 20 iterations", [](ResponseOptions& o) { o.iterations = 20; }},
      {"soft step, 4 substeps (solver = soft)", [](ResponseOptions& o) { o.solver = SolverKind::Soft; }},
  };
  std::printf("\n## Solver choices (%d iterations unless stated)\n\n", ResponseOptions{}.iterations);
  std::printf("| solver | stack of 10: drift (voxel/s) | stack: max speed at end (m/s) | 1000:1: heavy sank (voxels) | 1000:1: max penetration (voxels) | 500 rocks: max speed at end (m/s) | 500 rocks: steps/s |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
  for (const Choice& c : choices) {
    ResponseOptions o;
    c.set(o);
    Scene s = stack(10, 0.05, 1.0 / 60.0, 10.0 * t, 2.0 * t, o);
    const Metrics ms = run(s);
    Scene r = massRatio(1000.0, 5.0 * t, o);
    const std::size_t heavy = r.movers.back();
    const double rest = r.world->bodies()[heavy].pose.position.z();
    const Metrics mr = run(r);
    const double sink = (rest - r.world->bodies()[heavy].pose.position.z()) / r.voxel;
    Scene p = cornerPile(500, 4, 4.0 * t, Budget::unlimited(), o);
    const Metrics mp = run(p);
    std::printf("| %s | %.3g | %.3g | %.3g | %.3g | %.3g | %.0f |\n", c.name, ms.drift, ms.final_max_speed, sink,
                mr.max_penetration, mp.final_max_speed, mp.steps_per_second);
    std::fflush(stdout);
  }

  // Ablations: what the swept test and the gyroscopic term buy.
  std::printf("\n## Ablations\n\n| scene | setting | outcome |\n|---|---|---|\n");
  for (const bool continuous : {true, false}) {
    ResponseOptions o;
    o.continuous = continuous;
    Scene scene = fastSphere(100.0, 0.5, o);
    const std::size_t ball = scene.movers.front();
    double lowest = 1e9;
    run(scene, [&](const World& w, int) { lowest = std::min(lowest, w.bodies()[ball].pose.position.z()); });
    std::printf("| 1-voxel sphere at 100 m/s | continuous = %s | %s (lowest centre %.1f voxels) |\n",
                continuous ? "on" : "off", lowest < 0.0 ? "tunnels through the plate" : "stopped at the plate",
                lowest / scene.voxel);
  }
  for (const bool gyroscopic : {true, false}) {
    ResponseOptions o;
    o.gyroscopic = gyroscopic;
    Scene scene = spinningRod(100.0, 10.0 * t, o);
    const std::size_t rod = scene.movers.front();
    const BodyState& b0 = scene.world->bodies()[rod];
    const double e0 = kineticEnergy(b0);
    const Vec3 l0 = worldInertia(b0) * b0.angular_velocity;
    double energy = 0.0, momentum = 0.0, min_axis = 1.0;
    run(scene, [&](const World& w, int) {
      const BodyState& b = w.bodies()[rod];
      energy = std::max(energy, std::abs(kineticEnergy(b) - e0) / e0);
      momentum = std::max(momentum, (worldInertia(b) * b.angular_velocity - l0).norm() / l0.norm());
      min_axis = std::min(min_axis, (b.pose.orientation.conjugate() * b.angular_velocity).y() / 100.0);
    });
    std::printf("| rod at 100 rad/s, intermediate axis | gyroscopic = %s | max energy change %.1e, max drift of L %.1e, min w_y/w0 %.2f |\n",
                gyroscopic ? "implicit midpoint" : "off", energy, momentum, min_axis);
  }
  return 0;
}
