// Narrow-phase benchmark: a full-depth PairTest (stepped until it resolves)
// against FCL's exact collide on BVHModel<OBBRSS> meshes of the same voxel
// shapes, on the same poses, side by side in one run.
//
// Pose sets, per shape pair (rock-rock, ring-L, cube-cube), all random
// orientations and approach directions:
//   overlapping  B moved along the direction to first contact, then 0.1 to 3
//                voxels further in; kept when FCL says colliding;
//   near-miss    first contact, then backed off by 0.05 to 1 voxel; kept when
//                FCL says separate (the hard case for a sphere hierarchy).
// First contact is found by conservative advancement on FCL's exact distance.
// Per pair time: thread CPU time over the set / poses, where each chunk of
// 50 poses is timed P times (default 5) and its fastest pass counts (the
// machine may be shared; a chunk fits in one time slice). PairTest runs twice: as the World uses it (a level
// that finds leaf pairs is finished, so the response gets all of them) and
// in first-contact mode (stops at the first leaf pair, the question FCL's
// default collide request answers). Agreement: both colliding, ours only (a false positive of
// the sphere approximation), FCL only (a missed collision: must be 0).
//
// Usage: bench_narrow_phase [--poses N] [--passes P] [--resolution R] [--levels L] [--smoke] [--markdown FILE]
//   --smoke: 50 poses, 1 pass: that the bench runs (scripts/bench_smoke.sh)
#include "fcl_mesh.hpp"
#include "pose_sampling.hpp"
#include "pair_test.hpp"
#include "tick_clock.hpp"

#include <fcl/narrowphase/collision.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace stc;

using stc_bench::threadCpuSeconds;

struct Shape {
  std::string name;
  VoxelShape voxels;
  Vec3 origin;
  SphereTree tree;
  std::shared_ptr<truth::FclMesh> mesh;
  double radius = 0.0;  // bounding radius of the mesh about the origin
};

Shape makeShape(const std::string& preset, const PresetParams& params, int levels) {
  Shape s{preset, makePreset(preset, params), Vec3::Zero(), SphereTree{}, nullptr, 0.0};
  s.origin = computeMassProperties(s.voxels, 1.0).centre_of_mass;
  s.tree = SphereTree::build(s.voxels, s.origin, SphereTreeOptions{levels, SphereFit::Tight});
  const truth::SurfaceMesh mesh = truth::buildSurfaceMesh(s.voxels, s.origin);
  for (const Vec3& v : mesh.vertices) s.radius = std::max(s.radius, v.norm());
  s.mesh = truth::toFclMesh(mesh);
  return s;
}

struct PoseSet {
  std::vector<Pose> a, b;
  std::vector<fcl::Transform3d> fa, fb;
  void add(const Pose& pa, const Pose& pb) {
    a.push_back(pa);
    b.push_back(pb);
    fa.push_back(truth::toFcl(pa));
    fb.push_back(truth::toFcl(pb));
  }
  std::size_t size() const { return a.size(); }
};

// Distance along `dir` at which B first touches A coming in from far away
// (conservative advancement: moving B by the exact gap cannot skip a contact).
// Negative when B reaches A's centre without touching (e.g. through a hole).
double firstContact(const Shape& A, const Pose& pa, const Shape& B, Quat qb, const Vec3& dir) {
  double d = A.radius + B.radius + 1e-3;
  for (int it = 0; it < 200; ++it) {
    Pose pb;
    pb.orientation = qb;
    pb.position = pa.position + d * dir;
    const double gap = truth::exactDistance(*A.mesh, pa, *B.mesh, pb);
    if (gap < 1e-7 * A.voxels.voxelSize()) return d;
    d -= gap;
    if (d <= 0.0) return -1.0;
  }
  return d;
}

void makeSets(const Shape& A, const Shape& B, std::size_t count, std::uint64_t seed, PoseSet& overlapping,
              PoseSet& near_miss) {
  truth::Rng rng(seed);
  const double voxel = A.voxels.voxelSize();
  while (overlapping.size() < count || near_miss.size() < count) {
    Pose pa;
    pa.orientation = truth::randomRotation(rng);
    const Quat qb = truth::randomRotation(rng);
    const Vec3 dir = truth::randomDirection(rng);
    const double contact = firstContact(A, pa, B, qb, dir);
    if (contact <= 0.0) continue;
    Pose pb;
    pb.orientation = qb;
    if (overlapping.size() < count) {
      pb.position = pa.position + std::max(0.0, contact - voxel * truth::randomUniform(rng, 0.1, 3.0)) * dir;
      if (truth::exactCollide(*A.mesh, pa, *B.mesh, pb)) overlapping.add(pa, pb);
    }
    if (near_miss.size() < count) {
      pb.position = pa.position + (contact + voxel * truth::randomUniform(rng, 0.05, 1.0)) * dir;
      if (!truth::exactCollide(*A.mesh, pa, *B.mesh, pb)) near_miss.add(pa, pb);
    }
  }
}

struct Result {
  double all_us = 0.0, first_us = 0.0, fcl_us = 0.0;  // per pair
  double sphere_tests = 0.0, first_tests = 0.0, steps = 0.0;  // mean per pair
  std::size_t both = 0, ours_only = 0, fcl_only = 0, neither = 0;
  std::size_t mode_disagreements = 0;  // all-pairs and first-contact answers differ (must be 0)
};

// PairTests over poses [begin, end) of the set; returns CPU seconds.
double timeOurs(const Shape& A, const Shape& B, const PoseSet& set, std::size_t begin, std::size_t end,
                PairTest& test, std::vector<char>& colliding, std::int64_t& tests, std::int64_t& steps) {
  const double t0 = threadCpuSeconds();
  for (std::size_t i = begin; i < end; ++i) {
    test.reset(PairBody{0, &A.tree, &set.a[i]}, PairBody{1, &B.tree, &set.b[i]});
    while (!test.resolved()) test.step();
    colliding[i] = test.status() == PairStatus::Colliding;
    tests += test.sphereTests();
    steps += test.stepsDone();
  }
  return threadCpuSeconds() - t0;
}

double timeFcl(const Shape& A, const Shape& B, const PoseSet& set, std::size_t begin, std::size_t end,
               std::vector<char>& colliding) {
  const fcl::CollisionRequestd request;  // yes/no: stop at the first contact
  const double t0 = threadCpuSeconds();
  for (std::size_t i = begin; i < end; ++i) {
    fcl::CollisionResultd result;
    fcl::collide(A.mesh.get(), set.fa[i], B.mesh.get(), set.fb[i], request, result);
    colliding[i] = result.isCollision();
  }
  return threadCpuSeconds() - t0;
}

// The machine may be shared: each chunk of poses is short enough to fit in
// one time slice, is timed `passes` times, and its fastest pass counts.
Result run(const Shape& A, const Shape& B, const PoseSet& set, int passes) {
  constexpr std::size_t kChunk = 50;
  Result r;
  const std::size_t n = set.size();
  std::vector<char> all(n), first(n), exact(n);
  PairTest all_pairs, first_contact;
  first_contact.setFirstContactOnly(true);
  double sum_all = 0.0, sum_first = 0.0, sum_fcl = 0.0;
  std::int64_t tests = 0, first_tests = 0, steps = 0;
  for (std::size_t begin = 0; begin < n; begin += kChunk) {
    const std::size_t end = std::min(n, begin + kChunk);
    double best_all = 1e30, best_first = 1e30, best_fcl = 1e30;
    for (int pass = 0; pass < passes; ++pass) {
      std::int64_t t = 0, t_first = 0, s = 0, s_first = 0;
      best_all = std::min(best_all, timeOurs(A, B, set, begin, end, all_pairs, all, t, s));
      best_first = std::min(best_first, timeOurs(A, B, set, begin, end, first_contact, first, t_first, s_first));
      best_fcl = std::min(best_fcl, timeFcl(A, B, set, begin, end, exact));
      if (pass == 0) {
        tests += t;
        first_tests += t_first;
        steps += s;
      }
    }
    sum_all += best_all;
    sum_first += best_first;
    sum_fcl += best_fcl;
  }
  r.all_us = 1e6 * sum_all / n;
  r.first_us = 1e6 * sum_first / n;
  r.fcl_us = 1e6 * sum_fcl / n;
  r.sphere_tests = static_cast<double>(tests) / n;
  r.first_tests = static_cast<double>(first_tests) / n;
  r.steps = static_cast<double>(steps) / n;
  for (std::size_t i = 0; i < n; ++i) {
    r.mode_disagreements += all[i] != first[i];
    if (all[i] && exact[i]) ++r.both;
    else if (all[i]) ++r.ours_only;
    else if (exact[i]) ++r.fcl_only;
    else ++r.neither;
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t poses = 3000;
  int levels = 4;
  int passes = 5;
  PresetParams params;  // resolution 8, 5 cm voxels
  std::string markdown;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--poses" && has_value) poses = std::strtoul(argv[++i], nullptr, 10);
    else if (arg == "--resolution" && has_value) params.resolution = std::atoi(argv[++i]);
    else if (arg == "--levels" && has_value) levels = std::atoi(argv[++i]);
    else if (arg == "--passes" && has_value) passes = std::max(1, std::atoi(argv[++i]));
    else if (arg == "--markdown" && has_value) markdown = argv[++i];
    else if (arg == "--smoke") poses = 50, passes = 1;
    else {
      std::fprintf(stderr, "usage: %s [--poses N] [--passes P] [--resolution R] [--levels L] [--smoke] [--markdown FILE]\n", argv[0]);
      return 2;
    }
  }

  const struct {
    const char* a;
    const char* b;
    std::uint32_t seed_b;
  } kinds[] = {{"rock", "rock", 2}, {"ring", "L", 1}, {"cube", "cube", 1}};

  std::ostringstream table;
  table << "| pair | set | poses | PairTest us | FCL us | FCL/PairTest | PairTest first-contact us | "
           "FCL/first-contact | sphere tests | first-contact tests | steps | both collide | PairTest only | "
           "FCL only |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  double worst_ratio = 1e30, worst_first_ratio = 1e30;
  std::size_t missed = 0, disagreements = 0;
  for (const auto& kind : kinds) {
    const Shape A = makeShape(kind.a, params, levels);
    PresetParams pb = params;
    pb.seed = kind.seed_b;
    const Shape B = makeShape(kind.b, pb, levels);
    PoseSet overlapping, near_miss;
    makeSets(A, B, poses, 7, overlapping, near_miss);
    for (int s = 0; s < 2; ++s) {
      const PoseSet& set = s == 0 ? overlapping : near_miss;
      const Result r = run(A, B, set, passes);
      const double ratio = r.fcl_us / r.all_us, first_ratio = r.fcl_us / r.first_us;
      worst_ratio = std::min(worst_ratio, ratio);
      worst_first_ratio = std::min(worst_first_ratio, first_ratio);
      missed += r.fcl_only;
      disagreements += r.mode_disagreements;
      char line[512];
      std::snprintf(line, sizeof line,
                    "| %s-%s | %s | %zu | %.2f | %.2f | %.1fx | %.2f | %.1fx | %.0f | %.0f | %.1f | %zu | %zu | %zu |\n",
                    kind.a, kind.b, s == 0 ? "overlapping" : "near-miss", set.size(), r.all_us, r.fcl_us, ratio,
                    r.first_us, first_ratio, r.sphere_tests, r.first_tests, r.steps, r.both, r.ours_only,
                    r.fcl_only);
      table << line;
      std::fputs(line, stdout);
      std::fflush(stdout);
    }
  }
  char summary[512];
  std::snprintf(summary, sizeof summary,
                "\nresolution %d, %d levels. Slowest ratio FCL/PairTest %.1fx (all leaf pairs), %.1fx (first "
                "contact); target >= 5x: %s. Missed collisions (FCL only): %zu. Answers differing between the "
                "two PairTest modes: %zu.\n",
                params.resolution, levels, worst_ratio, worst_first_ratio, worst_ratio >= 5.0 ? "met" : "NOT met",
                missed, disagreements);
  std::fputs(summary, stdout);
  if (!markdown.empty()) {
    std::ofstream out(markdown);
    out << table.str() << summary;
  }
  return 0;
}
