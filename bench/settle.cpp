// How a pile falls asleep (issue 9 item 3, docs/sleeping.md): a built-in
// scene run under gravity, with a line every --every seconds of simulated
// time on the awake movers, then a timed window of the settled scene.
//
// Each line: bodies asleep; awake movers and, of them, those moving by their
// velocity of the moment (|v| above 0.05 m/s or |w| above 0.1 rad/s: the
// rest test before the one by motion, rest_test.hpp); the islands of
// the awake movers (union-find over the tick's contacts: count, largest);
// speeds of the moving ones (p50 / max of |v| and |w|) and how far they went
// over the interval against the path their stored speed adds up to
// (drift/path near 1: creeping; near 0: jitter in place), and the same for
// the angle turned (turned/turn near 0: rocking to and fro); where they are
// (by the contact normals with static bodies: on a slope, on flat ground,
// against a wall, on rocks only); pairs tested and contacts in the last tick.
// A second line ("restless") counts the bodies failing the rest test
// (World::isRestless), the ones that keep their islands awake: per tick mean
// and max over the interval, how many different bodies, where they are, how
// far they went and how many travelled faster than 0.05 m/s on average.
//
// Then --seconds of ticks timed in thread-CPU ms (p50 / p99 / max), with the
// work done each tick (pair tests set up, sphere tests, contacts).
//
// Usage: bench_settle [--scene NAME] [--bodies N] [--settle S] [--seconds S] [--every S]
//   --scene    built-in scene (default rockfall)
//   --bodies   movable entities (default 5000)
//   --settle   simulated seconds at most before the timed window (default 60);
//              it ends earlier once every mover sleeps
//   --seconds  timed window (default 5)
//   --every    seconds between lines (default 5)
//   --smoke    200 bodies, 0.1 s settling, 0.05 s timed: that the bench runs, scripts/bench_smoke.sh
//   (the timed window also prints its wall ms per tick by phase)
//   --sleep-off  WorldConfig::sleeping.enabled = false (what the pile costs awake)
//   --rolling C  every body's Material::rolling_resistance set to C after the
//              scene is built (default: the scene's own)
//   --solver NAME  ResponseOptions::solver: sequential (default), jacobi or soft
//   --iterations N  ResponseOptions::iterations (default: the World's)
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "tick_clock.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

namespace {

using namespace stc;

struct Options {
  SceneKind scene = SceneKind::Rockfall;
  int bodies = 5000;
  double settle = 60.0;
  double seconds = 5.0;
  double every = 5.0;
  bool sleep_off = false;
  double rolling = -1.0;  // < 0: the scene's
  SolverKind solver = ResponseOptions{}.solver;
  int iterations = ResponseOptions{}.iterations;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw InputError(a, "needs a value");
      return argv[++i];
    };
    if (a == "--scene") o.scene = parseScene(next());
    else if (a == "--bodies") o.bodies = std::stoi(next());
    else if (a == "--settle") o.settle = std::stod(next());
    else if (a == "--seconds") o.seconds = std::stod(next());
    else if (a == "--every") o.every = std::stod(next());
    else if (a == "--sleep-off") o.sleep_off = true;
    else if (a == "--rolling") o.rolling = std::stod(next());
    else if (a == "--solver") o.solver = parseSolverKind(next());
    else if (a == "--iterations") o.iterations = std::stoi(next());
    else if (a == "--smoke") o.bodies = 200, o.settle = 0.1, o.seconds = 0.05, o.every = 0.05;
    else throw InputError(a, "unknown option");
  }
  if (!(o.every > 0.0)) throw InputError("--every", "must be > 0");
  return o;
}

// Counted as moving: the thresholds of the rest test by velocity.
constexpr double kSpeed = 0.05;  // m/s
constexpr double kSpin = 0.1;    // rad/s

// Where a moving body is, by its contacts with static bodies this tick.
enum Place { kSlope, kFlat, kWall, kRocksOnly, kPlaces };
const char* const kPlaceNames[kPlaces] = {"slope", "flat", "wall", "rocks-only"};

class Diagnosis {
 public:
  Diagnosis(const World& world, const SceneSpec& spec) : world_(world), spec_(spec) {
    for (EntityId id : spec.movers) dense_.push_back(*world.indexOf(id));
    start_.resize(dense_.size());
    start_turn_.resize(dense_.size());
    path_.assign(dense_.size(), 0.0);
    turn_.assign(dense_.size(), 0.0);
    restless_ever_.assign(dense_.size(), 0);
    restart();
  }

  void restart() {
    for (std::size_t k = 0; k < dense_.size(); ++k) {
      start_[k] = world_.bodies()[dense_[k]].pose.position;
      start_turn_[k] = world_.bodies()[dense_[k]].pose.orientation;
    }
    std::fill(path_.begin(), path_.end(), 0.0);
    std::fill(turn_.begin(), turn_.end(), 0.0);
    std::fill(restless_ever_.begin(), restless_ever_.end(), 0);
    restless_ticks_ = 0;
    restless_sum_ = 0;
    restless_max_ = 0;
  }

  void tick(double dt) {
    dt_ = dt;
    int restless = 0;
    for (std::size_t k = 0; k < dense_.size(); ++k) {
      path_[k] += world_.bodies()[dense_[k]].linear_velocity.norm() * dt;
      turn_[k] += world_.bodies()[dense_[k]].angular_velocity.norm() * dt;
      if (!world_.isRestless(world_.entityIds()[dense_[k]])) continue;
      ++restless;
      restless_ever_[k] = 1;
    }
    ++restless_ticks_;
    restless_sum_ += restless;
    restless_max_ = std::max(restless_max_, restless);
  }

  void line(double t, const TickReport& r) {
    const std::vector<BodyState>& bodies = world_.bodies();
    const std::size_t n = bodies.size();
    // Islands of the awake movers, as the World joins them.
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), 0u);
    place_.assign(n, kRocksOnly);
    for (const Contact& c : world_.contacts()) {
      const bool sa = bodies[c.index_a].is_static, sb = bodies[c.index_b].is_static;
      if (sa != sb) {
        const std::uint32_t mover = sa ? c.index_b : c.index_a;
        const double up = std::abs(c.normal.z());
        const Place p = up > 0.98 ? kFlat : (up > 0.7 ? kSlope : kWall);
        place_[mover] = std::min(place_[mover], p);
        continue;
      }
      if (sa || world_.isSleeping(world_.entityIds()[c.index_a]) ||
          world_.isSleeping(world_.entityIds()[c.index_b])) continue;
      const std::uint32_t ra = find(c.index_a), rb = find(c.index_b);
      if (ra != rb) parent_[std::max(ra, rb)] = std::min(ra, rb);
    }
    std::vector<int> size(n, 0);
    int islands = 0, largest = 0, awake = 0, moving = 0, lin = 0, ang = 0;
    int places[kPlaces] = {0, 0, 0, 0};
    std::vector<double> v, w, drift, path, turned, turn;
    for (std::size_t k = 0; k < dense_.size(); ++k) {
      const std::size_t i = dense_[k];
      if (world_.isSleeping(world_.entityIds()[i])) continue;
      ++awake;
      const std::uint32_t root = find(static_cast<std::uint32_t>(i));
      if (size[root]++ == 0) ++islands;
      largest = std::max(largest, size[root]);
      const double vi = bodies[i].linear_velocity.norm(), wi = bodies[i].angular_velocity.norm();
      const bool over_v = vi > kSpeed, over_w = wi > kSpin;
      lin += over_v ? 1 : 0;
      ang += over_w ? 1 : 0;
      if (!over_v && !over_w) continue;
      ++moving;
      ++places[place_[i]];
      v.push_back(vi);
      w.push_back(wi);
      drift.push_back((bodies[i].pose.position - start_[k]).norm());
      path.push_back(path_[k]);
      turned.push_back(Eigen::AngleAxisd(bodies[i].pose.orientation * start_turn_[k].conjugate()).angle());
      turn.push_back(turn_[k]);
    }
    const double sum_drift = std::accumulate(drift.begin(), drift.end(), 0.0);
    const double sum_path = std::accumulate(path.begin(), path.end(), 0.0);
    const double sum_turned = std::accumulate(turned.begin(), turned.end(), 0.0);
    const double sum_turn = std::accumulate(turn.begin(), turn.end(), 0.0);
    std::printf(
        "t=%5.1f asleep=%5zu awake=%5d moving=%5d (v>%.2g: %d, w>%.2g: %d) islands=%d largest=%d"
        " |v| p50/max=%.3f/%.3f |w| p50/max=%.3f/%.3f drift/path=%.2f turned/turn=%.2f",
        t, r.bodies.sleeping, awake, moving, kSpeed, lin, kSpin, ang, islands, largest, stc_bench::percentile(v, 0.5),
        stc_bench::maxOf(v), stc_bench::percentile(w, 0.5), stc_bench::maxOf(w),
        sum_path > 0.0 ? sum_drift / sum_path : 0.0, sum_turn > 0.0 ? sum_turned / sum_turn : 0.0);
    std::printf(" where:");
    for (int p = 0; p < kPlaces; ++p) std::printf(" %s=%d", kPlaceNames[p], places[p]);
    std::printf(" pairs=%zu contacts=%zu\n", world_.pairCount(), r.response.contacts);
    restlessLine();
    std::fflush(stdout);
    restart();
  }

 private:
  // The bodies failing the rest test (World::isRestless): what keeps their
  // islands awake. Per tick mean / max over the interval, how many different
  // bodies that was, and of those: where they are (static contacts at the
  // line's tick), how far they went over the interval (p50 / max) and how
  // many of them moved faster than kSpeed on average (sliding or rolling
  // away, against jitter in place).
  void restlessLine() {
    const std::vector<BodyState>& bodies = world_.bodies();
    int distinct = 0, travelling = 0;
    int places[kPlaces] = {0, 0, 0, 0};
    std::vector<double> drift;
    for (std::size_t k = 0; k < dense_.size(); ++k) {
      if (restless_ever_[k] == 0) continue;
      ++distinct;
      ++places[place_[dense_[k]]];
      const double d = (bodies[dense_[k]].pose.position - start_[k]).norm();
      drift.push_back(d);
      travelling += d > kSpeed * elapsed() ? 1 : 0;
    }
    std::printf("  restless per tick mean/max=%.1f/%d bodies=%d where:", restless_ticks_ > 0 ?
                static_cast<double>(restless_sum_) / restless_ticks_ : 0.0, restless_max_, distinct);
    for (int p = 0; p < kPlaces; ++p) std::printf(" %s=%d", kPlaceNames[p], places[p]);
    std::printf(" drift p50/max=%.4f/%.4f m travelling(>%.2g m/s)=%d\n", stc_bench::percentile(drift, 0.5),
                stc_bench::maxOf(drift), kSpeed, travelling);
  }
  double elapsed() const { return restless_ticks_ * dt_; }

  std::uint32_t find(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  const World& world_;
  const SceneSpec& spec_;
  std::vector<std::size_t> dense_;
  std::vector<Vec3> start_;
  std::vector<Quat> start_turn_;
  std::vector<double> path_, turn_;
  std::vector<std::uint32_t> parent_;
  std::vector<Place> place_;
  std::vector<std::uint8_t> restless_ever_;
  int restless_ticks_ = 0, restless_max_ = 0;
  long restless_sum_ = 0;
  double dt_ = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  try {
    const Options opt = parse(argc, argv);
    WorldConfig config;
    config.sleeping.enabled = !opt.sleep_off;
    config.response.solver = opt.solver;
    config.response.iterations = opt.iterations;
    SceneParams params;
    params.entities = opt.bodies;
    SceneWorld scene = makeSceneWorld(opt.scene, params, config);
    World& world = scene.world;
    if (opt.rolling >= 0.0) {
      for (BodyState& b : world.bodies()) b.material.rolling_resistance = opt.rolling;
    }
    const SceneSpec& spec = scene.spec;
    const double dt = spec.dt;
    double rolling = 0.0;
    for (const BodyState& b : world.bodies()) rolling = std::max(rolling, b.material.rolling_resistance);
    std::printf("scene=%s bodies=%d dt=%.5f solver=%s iterations=%d sleeping=%s (linear_speed %.3g m/s for %.3g s) "
                "rolling_resistance=%.3g\n",
                toString(opt.scene), opt.bodies, dt, toString(opt.solver), opt.iterations, opt.sleep_off ? "off" : "on",
                config.sleeping.linear_speed, config.sleeping.time_to_sleep, rolling);
    Diagnosis diagnosis(world, spec);
    const int every = std::max(1, static_cast<int>(std::lround(opt.every / dt)));
    const int settle = static_cast<int>(std::lround(opt.settle / dt));
    double asleep_at = -1.0;
    TickReport r;
    int t = 0;
    while (t < settle) {
      r = world.step(dt, Budget::unlimited());
      ++t;
      diagnosis.tick(dt);
      if (t % every == 0) diagnosis.line(t * dt, r);
      if (r.bodies.sleeping == spec.movers.size()) {
        asleep_at = t * dt;
        break;
      }
    }
    if (t % every != 0) diagnosis.line(t * dt, r);
    std::printf("settled: all %zu movers asleep at t=%s\n", spec.movers.size(),
                asleep_at >= 0.0 ? std::to_string(asleep_at).c_str() : "never (within --settle)");

    std::vector<double> cpu, pairs, tests, contacts;
    double integrate = 0.0, broad = 0.0, sweep = 0.0, narrow = 0.0, response = 0.0, total = 0.0;  // wall s
    std::size_t asleep_min = spec.movers.size();
    const int timed = static_cast<int>(std::lround(opt.seconds / dt));
    for (int k = 0; k < timed; ++k) {
      const double c0 = stc_bench::threadCpuSeconds();
      r = world.step(dt, Budget::unlimited());
      cpu.push_back(1e3 * (stc_bench::threadCpuSeconds() - c0));
      pairs.push_back(static_cast<double>(world.pairCount()));
      tests.push_back(static_cast<double>(r.detection.sphere_tests));
      contacts.push_back(static_cast<double>(r.response.contacts));
      asleep_min = std::min(asleep_min, r.bodies.sleeping);
      integrate += r.phases.integrate_s;
      broad += r.phases.broad_s;
      sweep += r.phases.sweep_s;
      narrow += r.phases.narrow_s;
      response += r.phases.response_s;
      total += r.phases.total_s;
    }
    const double ms = 1e3 / std::max(timed, 1);
    std::printf("phases, wall ms per tick: integrate %.3f broad %.3f sweep %.3f narrow %.3f response %.3f"
                " other %.3f total %.3f\n",
                integrate * ms, broad * ms, sweep * ms, narrow * ms, response * ms,
                (total - integrate - broad - sweep - narrow - response) * ms, total * ms);
    std::printf(
        "SETTLED scene=%s bodies=%d asleep_at_s=%.2f asleep_min=%zu ticks=%d cpu_ms p50=%.3f p99=%.3f max=%.3f"
        " pair_tests_mean=%.1f sphere_tests_mean=%.1f contacts_mean=%.1f\n",
        toString(opt.scene), opt.bodies, asleep_at, asleep_min, timed, stc_bench::percentile(cpu, 0.5),
        stc_bench::percentile(cpu, 0.99), stc_bench::maxOf(cpu), stc_bench::meanOf(pairs),
        stc_bench::meanOf(tests), stc_bench::meanOf(contacts));
  } catch (const InputError& e) {
    std::fprintf(stderr, "bench_settle: %s\n", e.what());
    return 2;
  }
  return 0;
}
