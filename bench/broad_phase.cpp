// Broad-phase benchmark: stc::SweepAndPrune against FCL's broad-phase managers
// (DynamicAABBTree, its array variant, SaP) on the same coherent movers, side
// by side in one run. Each tick, timed: set every box (ours: setBox; FCL:
// setTranslation + computeAABB), update the manager, collect the overlapping
// pairs (no narrow phase). Pair counts must agree on every tick.
//
// Then the whole stc::World tick (integrate, broad, narrow at full depth,
// response) on rocks and cubes at the same density, N = 1k..50k, with the
// fitted exponent of time per tick against N.
//
// Usage: bench_broad_phase [--quick|--smoke]  (--quick: smaller N, 20 ticks; --smoke: one small N, 3 ticks)
// Prints three markdown tables.
#include "sphere_tree_collision/voxel_shape.hpp"
#include "sphere_tree_collision/world.hpp"
#include "sweep_and_prune.hpp"

#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree_array.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

// Thread CPU time: the machine may be shared, and time spent descheduled is
// nobody's work. (Wall time on an idle machine agrees to within noise.)
double cpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}
using stc::Vec3;

// N unit cubes in a cube world at fixed density: 1 cube per 8 unit^3, so each
// cube overlaps about one other. Each moves `speed` box sides per tick in a
// slowly turning direction; walls reflect.
class Movers {
 public:
  Movers(std::size_t count, double speed, unsigned seed)
      : side_(std::cbrt(8.0 * static_cast<double>(count))), speed_(speed), rng_(seed), pos_(count), vel_(count) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < count; ++i) {
      pos_[i] = Vec3(u(rng_), u(rng_), u(rng_)) * side_;
      vel_[i] = randomDirection() * speed_;
    }
  }

  void advance() {
    for (std::size_t i = 0; i < pos_.size(); ++i) {
      vel_[i] = (vel_[i] + randomDirection() * (0.1 * speed_)).normalized() * speed_;
      pos_[i] += vel_[i];
      for (int a = 0; a < 3; ++a) {
        if (pos_[i][a] < 0.0 || pos_[i][a] > side_) vel_[i][a] = -vel_[i][a];
        pos_[i][a] = std::clamp(pos_[i][a], 0.0, side_);
      }
    }
  }

  const std::vector<Vec3>& positions() const { return pos_; }

 private:
  Vec3 randomDirection() {
    std::normal_distribution<double> g(0.0, 1.0);
    return Vec3(g(rng_), g(rng_), g(rng_)).normalized();
  }

  double side_;
  double speed_;
  std::mt19937 rng_;
  std::vector<Vec3> pos_, vel_;
};

constexpr double kHalf = 0.5;  // cube half side

// One broad phase under test: load() registers the boxes at their first
// positions (not timed); tick() moves them and returns the pair count.
struct Contender {
  std::string name;
  std::function<void(const std::vector<Vec3>&)> load;
  std::function<std::size_t(const std::vector<Vec3>&)> tick;
  std::function<void()> unload;
};

Contender ours() {
  auto sap = std::make_shared<stc::SweepAndPrune>();
  auto boxOf = [](const Vec3& p) {
    stc::Aabb b;
    b.min = p - Vec3::Constant(kHalf);
    b.max = p + Vec3::Constant(kHalf);
    return b;
  };
  Contender c;
  c.name = "stc SaP";
  c.load = [sap, boxOf](const std::vector<Vec3>& pos) {
    for (std::size_t i = 0; i < pos.size(); ++i) sap->add(static_cast<stc::EntityId>(i), boxOf(pos[i]));
    sap->update();
  };
  c.tick = [sap, boxOf](const std::vector<Vec3>& pos) {
    for (std::size_t i = 0; i < pos.size(); ++i) sap->setBox(static_cast<stc::EntityId>(i), boxOf(pos[i]));
    sap->update();
    return sap->pairs().size();
  };
  c.unload = [sap] { *sap = stc::SweepAndPrune(); };
  return c;
}

struct FclPairs {
  std::vector<std::pair<const void*, const void*>> pairs;
};

bool collectPair(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  static_cast<FclPairs*>(data)->pairs.emplace_back(a, b);
  return false;  // keep going
}

template <typename Manager>
Contender fclManager(const std::string& name) {
  struct State {
    std::shared_ptr<fcl::Boxd> geometry = std::make_shared<fcl::Boxd>(2 * kHalf, 2 * kHalf, 2 * kHalf);
    std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
    std::unique_ptr<Manager> manager;
    FclPairs found;
  };
  auto s = std::make_shared<State>();
  Contender c;
  c.name = name;
  c.load = [s](const std::vector<Vec3>& pos) {
    s->manager = std::make_unique<Manager>();
    std::vector<fcl::CollisionObjectd*> raw;
    for (const Vec3& p : pos) {
      s->objects.push_back(std::make_unique<fcl::CollisionObjectd>(s->geometry));
      s->objects.back()->setTranslation(p);
      s->objects.back()->computeAABB();
      raw.push_back(s->objects.back().get());
    }
    s->manager->registerObjects(raw);
    s->manager->setup();
    s->found.pairs.reserve(4 * pos.size());
  };
  c.tick = [s](const std::vector<Vec3>& pos) {
    for (std::size_t i = 0; i < pos.size(); ++i) {
      s->objects[i]->setTranslation(pos[i]);
      s->objects[i]->computeAABB();
    }
    s->manager->update();
    s->found.pairs.clear();
    s->manager->collide(&s->found, collectPair);
    return s->found.pairs.size();
  };
  c.unload = [s] {
    s->manager.reset();
    s->objects.clear();
  };
  return c;
}

struct Result {
  double ms_per_tick = 0;
  double load_ms = 0;
  std::vector<std::size_t> pair_counts;  // per tick
};

Result run(Contender& c, std::size_t n, double speed, int ticks) {
  Movers movers(n, speed, 12345);  // same seed: same motion for every contender
  Result r;
  const double t0 = cpuMs();
  c.load(movers.positions());
  r.load_ms = cpuMs() - t0;
  double total = 0;
  for (int t = 0; t < ticks; ++t) {
    movers.advance();  // not timed: the same for everyone
    const double start = cpuMs();
    r.pair_counts.push_back(c.tick(movers.positions()));
    total += cpuMs() - start;
  }
  c.unload();
  r.ms_per_tick = total / ticks;
  return r;
}

struct Case {
  std::size_t n;
  double speed;  // box sides per tick
  int ticks;
};

// Runs every contender on one case; appends a markdown row; false on any
// pair-count disagreement.
bool runCase(std::vector<Contender>& contenders, const Case& k, std::ostringstream& table) {
  std::vector<Result> results;
  for (Contender& c : contenders) {
    results.push_back(run(c, k.n, k.speed, k.ticks));
    std::printf("N=%-6zu speed %.3f  %-26s load %8.1f ms  tick %8.3f ms  pairs first %zu last %zu\n", k.n,
                k.speed, c.name.c_str(), results.back().load_ms, results.back().ms_per_tick,
                results.back().pair_counts.front(), results.back().pair_counts.back());
    std::fflush(stdout);
  }
  bool agree = true;
  for (std::size_t c = 1; c < results.size(); ++c) {
    for (int t = 0; t < k.ticks; ++t) {
      if (results[c].pair_counts[t] != results[0].pair_counts[t]) {
        std::printf("!!!!! MISMATCH N=%zu tick %d: %s %zu pairs, %s %zu pairs !!!!!\n", k.n, t,
                    contenders[0].name.c_str(), results[0].pair_counts[t], contenders[c].name.c_str(),
                    results[c].pair_counts[t]);
        agree = false;
        break;
      }
    }
  }
  double fastest_fcl = results[1].ms_per_tick;
  for (std::size_t c = 2; c < results.size(); ++c) fastest_fcl = std::min(fastest_fcl, results[c].ms_per_tick);
  double mean_pairs = 0;
  for (std::size_t p : results[0].pair_counts) mean_pairs += static_cast<double>(p);
  mean_pairs /= k.ticks;
  char row[512];
  int len = std::snprintf(row, sizeof row, "| %zu | %.3f | %d | %.0f |", k.n, k.speed, k.ticks, mean_pairs);
  for (const Result& r : results) len += std::snprintf(row + len, sizeof row - len, " %.3f |", r.ms_per_tick);
  std::snprintf(row + len, sizeof row - len, " **%.2fx** |\n", fastest_fcl / results[0].ms_per_tick);
  table << row;
  return agree;
}

std::string tableHeader(const std::vector<Contender>& contenders) {
  std::ostringstream h;
  h << "| N | speed (box sides/tick) | ticks | mean pairs |";
  for (const Contender& c : contenders) h << ' ' << c.name << " ms/tick |";
  h << " FCL fastest / stc |\n|---|---|---|---|";
  for (std::size_t i = 0; i < contenders.size(); ++i) h << "---|";
  h << "---|\n";
  return h.str();
}

// --- whole World tick against N -------------------------------------------------

struct WorldRow {
  std::size_t n = 0;
  double total_ms = 0, integrate_ms = 0, broad_ms = 0, narrow_ms = 0, response_ms = 0;
  double broad_pairs = 0, colliding = 0;
};

WorldRow runWorld(std::size_t n, int ticks) {
  stc::WorldConfig config;
  config.max_entities = n;
  stc::World world(config);
  const stc::ShapeId shapes[2] = {world.addShape("rock", stc::makePreset("rock")),
                                  world.addShape("cube", stc::makePreset("cube"))};
  double box_side = 0;
  for (stc::ShapeId s : shapes) box_side = std::max(box_side, 2 * world.shape(s).bounding_radius);
  // Same density as above: one bounding cube per 8 cube volumes.
  const double side = box_side * std::cbrt(8.0 * static_cast<double>(n));
  const double dt = 1.0 / 60.0;
  const double speed = 0.02 * box_side / dt;  // 2% of a box side per tick
  std::mt19937 rng(777);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    stc::EntitySpec spec;
    spec.shape = shapes[i % 2];
    spec.pose.position = Vec3(u(rng), u(rng), u(rng)) * side;
    spec.pose.orientation = stc::Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    spec.linear_velocity = Vec3(g(rng), g(rng), g(rng)).normalized() * speed;
    spec.angular_velocity = Vec3(g(rng), g(rng), g(rng)) * 0.5;
    world.addEntity(spec);
  }
  const stc::Budget budget = stc::Budget::unlimited();
  for (int t = 0; t < 2; ++t) world.step(dt, budget);  // first sort, pools grown
  WorldRow row;
  row.n = n;
  for (int t = 0; t < ticks; ++t) {
    const double start = cpuMs();
    const stc::TickReport r = world.step(dt, budget);
    row.total_ms += cpuMs() - start;
    row.integrate_ms += 1e3 * r.phases.integrate_s;
    row.broad_ms += 1e3 * r.phases.broad_s;
    row.narrow_ms += 1e3 * r.phases.narrow_s;
    row.response_ms += 1e3 * r.phases.response_s;
    row.broad_pairs += static_cast<double>(r.detection.broad_pairs);
    row.colliding += static_cast<double>(r.detection.colliding + r.detection.unresolved_accepted);
  }
  for (double* v : {&row.total_ms, &row.integrate_ms, &row.broad_ms, &row.narrow_ms, &row.response_ms,
                    &row.broad_pairs, &row.colliding})
    *v /= ticks;
  return row;
}

// Least-squares slope of log(y) against log(n).
double fittedExponent(const std::vector<WorldRow>& rows, double WorldRow::*field) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const WorldRow& r : rows) {
    const double x = std::log(static_cast<double>(r.n)), y = std::log(r.*field);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double k = static_cast<double>(rows.size());
  return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

std::string worldTable(const std::vector<std::size_t>& sizes, int ticks) {
  std::vector<WorldRow> rows;
  for (std::size_t n : sizes) {
    rows.push_back(runWorld(n, ticks));
    const WorldRow& r = rows.back();
    std::printf("World N=%-6zu tick %8.3f ms (integrate %.3f broad %.3f narrow %.3f response %.3f) pairs %.0f\n",
                n, r.total_ms, r.integrate_ms, r.broad_ms, r.narrow_ms, r.response_ms, r.broad_pairs);
    std::fflush(stdout);
  }
  std::ostringstream t;
  t << "| N | ms/tick (CPU) | integrate ms | broad ms | narrow ms | response ms | broad pairs | colliding |\n"
       "|---|---|---|---|---|---|---|---|\n";
  char row[256];
  for (const WorldRow& r : rows) {
    std::snprintf(row, sizeof row, "| %zu | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f |\n", r.n, r.total_ms,
                  r.integrate_ms, r.broad_ms, r.narrow_ms, r.response_ms, r.broad_pairs, r.colliding);
    t << row;
  }
  std::snprintf(row, sizeof row,
                "\nFitted exponent (time ~ N^k, least squares on log-log): whole tick k = %.2f, "
                "broad phase k = %.2f, narrow phase k = %.2f.\n",
                fittedExponent(rows, &WorldRow::total_ms), fittedExponent(rows, &WorldRow::broad_ms),
                fittedExponent(rows, &WorldRow::narrow_ms));
  t << row;
  return t.str();
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, smoke = false;  // smoke: that the bench runs (scripts/bench_smoke.sh)
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) {
      quick = true;
    } else if (!std::strcmp(argv[i], "--smoke")) {
      smoke = true;
    } else {
      std::fprintf(stderr, "usage: %s [--quick|--smoke]\n", argv[0]);
      return 2;
    }
  }
  std::vector<Contender> contenders = {
      ours(),
      fclManager<fcl::DynamicAABBTreeCollisionManagerd>("FCL DynamicAABBTree"),
      fclManager<fcl::DynamicAABBTreeCollisionManager_Arrayd>("FCL DynamicAABBTree_Array"),
      fclManager<fcl::SaPCollisionManagerd>("FCL SaP"),
  };
  const int ticks = smoke ? 3 : quick ? 20 : 100;
  const double speed = 0.02;  // 2% of a box side per tick, e.g. 1.2 sides/s at 60 Hz

  std::ostringstream by_n, by_speed;
  by_n << tableHeader(contenders);
  by_speed << tableHeader(contenders);
  bool agree = true;
  const std::vector<std::size_t> sizes = smoke   ? std::vector<std::size_t>{500}
                                          : quick ? std::vector<std::size_t>{1000, 10000}
                                                  : std::vector<std::size_t>{1000, 10000, 50000};
  const std::size_t coherence_n = smoke ? 500 : 10000;
  // FCL's SaP manager takes ~1.5 s per tick at 50k: fewer ticks there, the same for all.
  for (std::size_t n : sizes) agree &= runCase(contenders, {n, speed, n >= 50000 ? 30 : ticks}, by_n);
  for (double s : {0.005, 0.02, 0.08}) agree &= runCase(contenders, {coherence_n, s, ticks}, by_speed);

  std::printf("\n### Scaling with N (speed %.3f)\n\n%s", speed, by_n.str().c_str());
  std::printf("\n### Coherence: N = %zu, speed varied\n\n%s", coherence_n, by_speed.str().c_str());
  std::printf("\npair counts %s on every tick\n", agree ? "AGREE" : "DISAGREE");
  std::fflush(stdout);

  const std::vector<std::size_t> world_sizes =
      smoke   ? std::vector<std::size_t>{300, 600}  // two sizes: the fitted exponent needs two points
      : quick ? std::vector<std::size_t>{1000, 2000, 5000}
              : std::vector<std::size_t>{1000, 2000, 5000, 10000, 20000, 50000};
  const std::string world = worldTable(world_sizes, smoke ? 2 : 10);
  std::printf("\n### Whole World tick against N (rocks and cubes, 2%% of a box per tick, full depth)\n\n%s",
              world.c_str());
  return agree ? 0 : 1;
}
