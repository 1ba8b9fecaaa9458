// Broad-phase benchmark: stc::SweepAndPrune against FCL's broad-phase managers
// (DynamicAABBTree, its array variant, SaP) on the same coherent movers, side
// by side in one run. Each tick, timed: set every box (ours: setBox; FCL:
// setTranslation + computeAABB), update the manager, collect the overlapping
// pairs (no narrow phase). Pair counts must agree on every tick.
//
// Usage: bench_broad_phase [--quick] [--markdown FILE]
//   --quick     N = 1k, 10k only, 30 ticks (a smoke run)
//   --markdown  also write the table to FILE (docs/broad_phase.md)
#include "sphere_tree_collision/sweep_and_prune.hpp"

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
#include <fstream>
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
// cube overlaps one other on average. Velocities random-walk; walls reflect.
class Movers {
 public:
  Movers(std::size_t count, unsigned seed)
      : side_(std::cbrt(8.0 * static_cast<double>(count))), rng_(seed), pos_(count), vel_(count) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < count; ++i) {
      pos_[i] = Vec3(u(rng_), u(rng_), u(rng_)) * side_;
      vel_[i] = Vec3(u(rng_) - 0.5, u(rng_) - 0.5, u(rng_) - 0.5) * 0.04;
    }
  }

  // One tick of motion: about 2% of a box side, so the sort stays nearly sorted.
  void advance() {
    std::uniform_real_distribution<double> u(-0.002, 0.002);
    for (std::size_t i = 0; i < pos_.size(); ++i) {
      vel_[i] += Vec3(u(rng_), u(rng_), u(rng_));
      pos_[i] += vel_[i];
      for (int a = 0; a < 3; ++a) {
        if (pos_[i][a] < 0.0 || pos_[i][a] > side_) vel_[i][a] = -vel_[i][a];
        pos_[i][a] = std::clamp(pos_[i][a], 0.0, side_);
      }
    }
  }

  const std::vector<Vec3>& positions() const { return pos_; }
  double side() const { return side_; }

 private:
  double side_;
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

Result run(Contender& c, std::size_t n, int ticks) {
  Movers movers(n, 12345);  // same seed: same motion for every contender
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

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string markdown;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--markdown") && i + 1 < argc) markdown = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--quick] [--markdown FILE]\n", argv[0]);
      return 2;
    }
  }
  struct Size { std::size_t n; int ticks; };
  const std::vector<Size> sizes = quick ? std::vector<Size>{{1000, 30}, {10000, 30}}
                                        : std::vector<Size>{{1000, 100}, {10000, 100}, {50000, 100}};

  std::vector<Contender> contenders = {
      ours(),
      fclManager<fcl::DynamicAABBTreeCollisionManagerd>("FCL DynamicAABBTree"),
      fclManager<fcl::DynamicAABBTreeCollisionManager_Arrayd>("FCL DynamicAABBTree_Array"),
      fclManager<fcl::SaPCollisionManagerd>("FCL SaP"),
  };

  std::ostringstream table;
  table << "| N | ticks | mean pairs |";
  for (const Contender& c : contenders) table << ' ' << c.name << " ms/tick |";
  table << " FCL fastest / ours |\n|---|---|---|";
  for (std::size_t i = 0; i < contenders.size(); ++i) table << "---|";
  table << "---|\n";

  bool all_agree = true;
  for (const Size& size : sizes) {
    std::vector<Result> results;
    for (Contender& c : contenders) {
      results.push_back(run(c, size.n, size.ticks));
      std::printf("N=%-6zu %-26s load %8.1f ms  tick %8.3f ms  pairs first %zu last %zu\n", size.n,
                  c.name.c_str(), results.back().load_ms, results.back().ms_per_tick,
                  results.back().pair_counts.front(), results.back().pair_counts.back());
      std::fflush(stdout);
    }
    for (std::size_t k = 1; k < results.size(); ++k) {
      for (int t = 0; t < size.ticks; ++t) {
        if (results[k].pair_counts[t] != results[0].pair_counts[t]) {
          std::printf("!!!!! MISMATCH N=%zu tick %d: %s %zu pairs, %s %zu pairs !!!!!\n", size.n, t,
                      contenders[0].name.c_str(), results[0].pair_counts[t],
                      contenders[k].name.c_str(), results[k].pair_counts[t]);
          all_agree = false;
          break;
        }
      }
    }
    double fastest_fcl = results[1].ms_per_tick;
    for (std::size_t k = 2; k < results.size(); ++k) fastest_fcl = std::min(fastest_fcl, results[k].ms_per_tick);
    double mean_pairs = 0;
    for (std::size_t p : results[0].pair_counts) mean_pairs += static_cast<double>(p);
    mean_pairs /= size.ticks;
    char row[512];
    int len = std::snprintf(row, sizeof row, "| %zu | %d | %.0f |", size.n, size.ticks, mean_pairs);
    for (const Result& r : results) len += std::snprintf(row + len, sizeof row - len, " %.3f |", r.ms_per_tick);
    std::snprintf(row + len, sizeof row - len, " %.1fx |\n", fastest_fcl / results[0].ms_per_tick);
    table << row;
  }

  std::printf("\n%s", table.str().c_str());
  std::printf("\npair counts %s on every tick\n", all_agree ? "AGREE" : "DISAGREE");
  if (!markdown.empty()) {
    std::ofstream out(markdown);
    out << table.str();
  }
  return all_agree ? 0 : 1;
}
