// Tightness of the sphere-trees: for each preset (resolution 16) and each level,
// both fits (paper = circumscribed cell sphere, tight = smallest sphere around
// the cell's surface voxels), side by side:
//   nodes     spheres at that level
//   worst     one-sided Hausdorff error of the level's union of spheres: the max
//             distance to the shape over sample points of the union's boundary
//             (points of a sphere outside the shape and outside every other
//             sphere of the level), as a fraction of the shape's largest extent
//             (the metric of the public sphere-tree toolkit)
//   mean      the mean of that distance over the same (area-uniform) samples
//   volume    total sphere volume / shape volume (spheres summed, not unioned)
// Distances are exact point-to-voxel distances; a subsample is cross-checked
// against FCL's distance to the shape's surface mesh (the reference), and the
// largest disagreement is printed.
//
// Usage: bench_tightness [--smoke] [--markdown FILE]   (writes docs/tightness.md when asked;
//   --smoke: the first preset only, that the bench runs, scripts/bench_smoke.sh)
#include "doc_output.hpp"
#include "fcl_mesh.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_union.hpp"

#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

namespace {

using stc::SphereFit;
using stc::SphereTree;
using stc::Vec3;
using stc::VoxelShape;

constexpr int kResolution = 16;
constexpr int kLevels = 5;              // 16 voxels: cells of 16, 8, 4, 2, 1 voxels
constexpr double kSampleSpacing = 0.2;  // voxels between neighbouring samples on a sphere
constexpr int kFclEvery = 97;           // cross-check every 97th boundary sample with FCL

struct LevelStats {
  int nodes = 0;
  double worst = 0.0;  // fraction of the largest extent
  double mean = 0.0;
  double volume_ratio = 0.0;
};

// Exact distance (voxel units) from p to the nearest surface voxel, searching
// the voxels within `bound` of p (bound must be >= the answer).
double distanceToShape(const VoxelShape& s, const std::vector<std::uint8_t>& surface, const Vec3& p,
                       double bound) {
  for (;; bound *= 2.0) {
    const int lo[3] = {std::max(0, static_cast<int>(std::floor(p.x() - bound))),
                       std::max(0, static_cast<int>(std::floor(p.y() - bound))),
                       std::max(0, static_cast<int>(std::floor(p.z() - bound)))};
    const int hi[3] = {std::min(s.nx() - 1, static_cast<int>(std::floor(p.x() + bound))),
                       std::min(s.ny() - 1, static_cast<int>(std::floor(p.y() + bound))),
                       std::min(s.nz() - 1, static_cast<int>(std::floor(p.z() + bound)))};
    double best2 = bound * bound;
    bool found = false;
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          if (!surface[s.index(i, j, k)]) continue;
          const Vec3 v(i, j, k);
          const double d2 = (v - p).cwiseMax(p - v - Vec3::Ones()).cwiseMax(0.0).squaredNorm();
          if (d2 <= best2) {
            best2 = d2;
            found = true;
          }
        }
    if (found) return std::sqrt(best2);
  }
}

struct FclCheck {
  double max_disagreement = 0.0;  // metres
  int points = 0;
};

LevelStats measureLevel(const VoxelShape& shape, const Vec3& origin, const SphereTree& tree, int level,
                        const std::vector<std::uint8_t>& surface, const stc::truth::FclMesh& mesh,
                        FclCheck& fcl_check) {
  const double a = shape.voxelSize();
  std::vector<stc::truth::Ball> balls;  // grid frame, voxel units
  std::vector<double> gap_bounds;
  for (std::int32_t i = tree.levelBegin(level); i < tree.levelBegin(level + 1); ++i) {
    const stc::SphereNode& n = tree.node(i);
    balls.push_back({(n.centre + origin) / a, n.radius / a});
    gap_bounds.push_back(n.h / a);
  }

  const auto fclSphere = std::make_shared<fcl::Sphered>(1e-9);
  double worst = 0.0, sum = 0.0, shape_volume = static_cast<double>(shape.occupiedCount());
  std::int64_t count = 0;
  double sphere_volume = 0.0;
  for (const stc::truth::Ball& b : balls) sphere_volume += 4.0 / 3.0 * M_PI * b.radius * b.radius * b.radius;
  stc::truth::forEachUnionBoundaryPoint(balls, kSampleSpacing, [&](std::size_t i, const Vec3& p) {
    const Vec3 f = p.array().floor();
    if (shape.occupied(int(f.x()), int(f.y()), int(f.z()))) return;  // inside the shape
    // h bounds the distance from this sphere to the part it covers, so also to the shape.
    const double d = distanceToShape(shape, surface, p, gap_bounds[i] + 1e-9);
    worst = std::max(worst, d);
    sum += d;
    if (++count % kFclEvery == 0) {
      fcl::DistanceRequestd request;
      fcl::DistanceResultd result;
      fcl::Transform3d at = fcl::Transform3d::Identity();
      at.translation() = p * a - origin;
      fcl::distance(&mesh, fcl::Transform3d::Identity(), fclSphere.get(), at, request, result);
      fcl_check.max_disagreement = std::max(fcl_check.max_disagreement, std::abs(result.min_distance - d * a));
      ++fcl_check.points;
    }
  });
  const double extent = std::max({shape.nx(), shape.ny(), shape.nz()});
  LevelStats st;
  st.nodes = static_cast<int>(balls.size());
  st.worst = worst / extent;
  st.mean = count > 0 ? sum / static_cast<double>(count) / extent : 0.0;
  st.volume_ratio = sphere_volume / shape_volume;
  return st;
}

std::string pct(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f%%", 100.0 * fraction);
  return buf;
}

using stc::bench::num;

}  // namespace

int main(int argc, char** argv) {
  std::string markdown_path;
  std::vector<std::string> presets = stc::presetNames();
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--markdown") == 0 && i + 1 < argc) {
      markdown_path = argv[++i];
    } else if (std::strcmp(argv[i], "--smoke") == 0) {
      presets.resize(1);
    } else {
      std::fprintf(stderr, "usage: %s [--smoke] [--markdown FILE]\n", argv[0]);
      return 2;
    }
  }

  std::ostringstream table;
  table << "| preset | level | nodes | paper worst | paper mean | paper vol | tight worst | tight mean | "
           "tight vol | tight/paper worst | tight/paper vol |\n"
        << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  FclCheck fcl_check;
  for (const std::string& name : presets) {
    stc::PresetParams params;
    params.resolution = kResolution;
    params.voxel_size = 0.05;
    const VoxelShape shape = stc::makePreset(name, params);
    const Vec3 origin = stc::computeMassProperties(shape, 1000.0).centre_of_mass;
    const auto mesh = stc::truth::makeFclMesh(shape, origin);
    std::vector<std::uint8_t> surface(shape.occupancy().size(), 0);
    for (int k = 0; k < shape.nz(); ++k)
      for (int j = 0; j < shape.ny(); ++j)
        for (int i = 0; i < shape.nx(); ++i) surface[shape.index(i, j, k)] = shape.isSurfaceVoxel(i, j, k);

    stc::SphereTreeOptions options;
    options.max_levels = kLevels;
    options.fit = SphereFit::Paper;
    const SphereTree paper = SphereTree::build(shape, origin, options);
    options.fit = SphereFit::Tight;
    const SphereTree tight = SphereTree::build(shape, origin, options);

    for (int level = 0; level < paper.levelCount(); ++level) {
      const LevelStats p = measureLevel(shape, origin, paper, level, surface, *mesh, fcl_check);
      const LevelStats t = measureLevel(shape, origin, tight, level, surface, *mesh, fcl_check);
      table << "| " << name << " | " << level << " | " << p.nodes << " | " << pct(p.worst) << " | "
            << pct(p.mean) << " | " << num(p.volume_ratio) << " | " << pct(t.worst) << " | " << pct(t.mean)
            << " | " << num(t.volume_ratio) << " | " << num(p.worst > 0 ? t.worst / p.worst : 1.0) << " | "
            << num(t.volume_ratio / p.volume_ratio) << " |\n";
    }
  }

  std::ostringstream doc;
  doc << "# Sphere-tree tightness\n\n"
      << "Generated by `bench_tightness --markdown docs/tightness.md` (bench/tightness.cpp). Presets at "
      << "resolution " << kResolution << " (voxels along the largest extent), octree depth " << kLevels
      << " (level 0 = the bounding cube, level 4 = single voxels); the sphere preset is one exact sphere.\n\n"
      << "- **worst / mean**: one-sided Hausdorff error of the level's union of spheres, as a fraction of the "
         "shape's largest extent: distance to the shape of sample points on the union's boundary (points of a "
         "sphere outside the shape and outside every other sphere of the level; about "
      << kSampleSpacing << " voxel apart, area-uniform).\n"
      << "- **vol**: total sphere volume (summed, overlaps counted twice) / shape volume.\n"
      << "- Same octree cells for both fits, so node counts agree; **tight/paper** < 1 means the tight fit is "
         "closer.\n\n"
      << table.str() << "\n"
      << "Reference check: " << fcl_check.points << " boundary samples re-measured with FCL "
      << "(distance from the point to the shape's surface mesh); largest disagreement with the exact voxel "
         "distance: "
      << num(fcl_check.max_disagreement * 1e3, "%.2g") << " mm (voxel size " << 0.05 * 1e3 << " mm).\n";

  return stc::bench::printAndWrite(doc.str(), markdown_path);
}
