// Named voxel shapes a scene can use. Every preset spans `resolution` voxels
// along its largest extent, and each is built deterministically.
#include "sphere_tree_collision/voxel_shape.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace stc {
namespace {

constexpr int kMaxResolution = 256;

// std::mt19937's output is fixed by the standard, but the std distributions are
// not; convert by hand so a seed means the same rock on every platform.
double uniform(std::mt19937& rng, double lo, double hi) {
  return lo + (hi - lo) * (static_cast<double>(rng()) / 4294967296.0);
}

struct Grid {
  int nx, ny, nz;
  std::vector<std::uint8_t> occ;
  Grid(int x, int y, int z) : nx(x), ny(y), nz(z), occ(static_cast<std::size_t>(x) * y * z, 0) {}
  // A preset's working grid, refused before it is filled when it is larger
  // than the limit: filling a rock of resolution 256 (8 million cells, a few
  // fills as it grows) took seconds before VoxelShape::create refused it.
  Grid(int x, int y, int z, const VoxelLimits& limits) : Grid((validateGridCells(x, y, z, limits), x), y, z) {}
  std::size_t at(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k);
  }
  // Sets every voxel whose centre (grid units, relative to the grid centre) passes `inside`.
  template <typename F>
  void fill(F inside) {
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          const Vec3 p(i + 0.5 - nx * 0.5, j + 0.5 - ny * 0.5, k + 0.5 - nz * 0.5);
          occ[at(i, j, k)] = inside(p) ? 1 : 0;
        }
  }
};

// Keeps only the 6-connected component of `grid` holding voxel `seed`.
void keepComponent(Grid& grid, int si, int sj, int sk) {
  std::vector<std::uint8_t> keep(grid.occ.size(), 0);
  std::vector<std::array<int, 3>> stack{{si, sj, sk}};
  keep[grid.at(si, sj, sk)] = 1;
  while (!stack.empty()) {
    const auto [i, j, k] = stack.back();
    stack.pop_back();
    const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                          {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
    for (const auto& n : nb) {
      if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= grid.nx || n[1] >= grid.ny || n[2] >= grid.nz) continue;
      const std::size_t id = grid.at(n[0], n[1], n[2]);
      if (grid.occ[id] && !keep[id]) {
        keep[id] = 1;
        stack.push_back({n[0], n[1], n[2]});
      }
    }
  }
  grid.occ.swap(keep);
}

// Shrinks the grid to the bounding box of its occupied voxels.
Grid cropped(const Grid& g) {
  int lo[3] = {g.nx, g.ny, g.nz}, hi[3] = {-1, -1, -1};
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        if (g.occ[g.at(i, j, k)]) {
          const int c[3] = {i, j, k};
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], c[a]);
            hi[a] = std::max(hi[a], c[a]);
          }
        }
  Grid out(hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1);
  for (int k = 0; k < out.nz; ++k)
    for (int j = 0; j < out.ny; ++j)
      for (int i = 0; i < out.nx; ++i) out.occ[out.at(i, j, k)] = g.occ[g.at(i + lo[0], j + lo[1], k + lo[2])];
  return out;
}

// A lumpy ellipsoid: a star-shaped radius function of random bumps, scaled up
// until its 6-connected core spans the full resolution along x.
Grid makeRock(int res, std::uint32_t seed, const VoxelLimits& limits) {
  std::mt19937 rng(seed);
  struct Bump { Vec3 dir; double amplitude; };
  std::array<Bump, 7> bumps;
  for (Bump& b : bumps) {
    Vec3 d;
    do d = Vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    while (d.squaredNorm() > 1.0 || d.squaredNorm() < 1e-3);
    b.dir = d.normalized();
    b.amplitude = uniform(rng, -0.22, 0.22);
  }
  const double aspect_y = uniform(rng, 0.65, 0.85), aspect_z = uniform(rng, 0.5, 0.7);
  const auto radius = [&](const Vec3& dir) {
    double r = 1.0;
    for (const Bump& b : bumps) {
      const double c = std::max(0.0, dir.dot(b.dir));
      r += b.amplitude * c * c * c;
    }
    return std::max(r, 0.5);
  };

  Grid grid(res, std::max(1, static_cast<int>(std::lround(res * aspect_y))),
            std::max(1, static_cast<int>(std::lround(res * aspect_z))), limits);
  const Vec3 half = Vec3(grid.nx, grid.ny, grid.nz) * 0.5;
  for (double scale = 0.8;; scale *= 1.05) {
    grid.fill([&](const Vec3& p) {
      const Vec3 q = p.cwiseQuotient(half * scale);
      const double n = q.norm();
      return n < 1e-12 || n < radius(q / n);
    });
    keepComponent(grid, grid.nx / 2, grid.ny / 2, grid.nz / 2);
    bool spans = true;  // does the component touch both x ends?
    for (int end : {0, grid.nx - 1}) {
      bool any = false;
      for (int k = 0; k < grid.nz && !any; ++k)
        for (int j = 0; j < grid.ny && !any; ++j) any = grid.occ[grid.at(end, j, k)] != 0;
      spans = spans && any;
    }
    if (spans) break;
  }
  return cropped(grid);
}

Grid makeNamed(const std::string& name, const PresetParams& p, const VoxelLimits& limits) {
  const int r = p.resolution;
  const int quarter = std::max(1, (r + 2) / 4);
  if (name == "cube") {
    Grid g(r, r, r, limits);
    g.fill([](const Vec3&) { return true; });
    return g;
  }
  if (name == "sphere") {
    Grid g(r, r, r, limits);
    const double radius = 0.5 * r;
    g.fill([&](const Vec3& q) { return q.norm() <= radius; });
    return g;
  }
  if (name == "rock") return makeRock(r, p.seed, limits);
  if (name == "rod") {
    Grid g(r, quarter, quarter, limits);
    g.fill([](const Vec3&) { return true; });
    return g;
  }
  if (name == "plate") {
    Grid g(r, r, std::max(1, (r + 4) / 8), limits);
    g.fill([](const Vec3&) { return true; });
    return g;
  }
  if (name == "L") {
    // Two arms of width w in the xy plane, joined at the origin corner.
    const int w = std::max(1, (r + 1) / 3);
    Grid g(r, r, w, limits);
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) g.occ[g.at(i, j, k)] = (i < w || j < w) ? 1 : 0;
    return g;
  }
  if (name == "ring") {
    // A washer: annulus between r/4 and r/2 about the z axis, with a through hole.
    if (r < 3) throw InputError("resolution", "the ring needs resolution >= 3 to have a hole");
    Grid g(r, r, quarter, limits);
    const double inner = 0.25 * r, outer = 0.5 * r;
    g.fill([&](const Vec3& q) {
      const double rho = std::hypot(q.x(), q.y());
      return rho >= inner && rho <= outer;
    });
    return g;
  }
  std::string known;
  for (const std::string& n : presetNames()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("preset", "unknown preset '" + name + "' (expected one of: " + known + ")");
}

}  // namespace

const std::vector<std::string>& presetNames() {
  static const std::vector<std::string> names = {"cube", "sphere", "rock", "rod", "plate", "L", "ring"};
  return names;
}

VoxelShape makePreset(const std::string& name, const PresetParams& params, const VoxelLimits& limits) {
  if (params.resolution < 1 || params.resolution > kMaxResolution) {
    throw InputError("resolution", "must be in [1, " + std::to_string(kMaxResolution) + "], got " +
                                       std::to_string(params.resolution));
  }
  Grid g = makeNamed(name, params, limits);
  VoxelShape shape = VoxelShape::create(g.nx, g.ny, g.nz, params.voxel_size, std::move(g.occ), limits);
  if (name == "sphere") shape.markSphere();
  return shape;
}

}  // namespace stc
