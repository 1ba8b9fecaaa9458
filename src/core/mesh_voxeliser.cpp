// Mesh -> solid VoxelShape: mark the voxels triangles cross, flood the outside
// from the grid border through unmarked voxels, and keep what it cannot reach.
#include "sphere_tree_collision/mesh_voxeliser.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace stc {
namespace {

constexpr int kMaxResolution = 1024;
// A triangle within this fraction of a voxel of a grid plane lies in it: it
// blocks the faces it covers instead of marking the voxels beside it, so an
// axis-aligned cube of 8 voxels gives exactly 8^3 voxels.
constexpr double kPlaneTolerance = 1e-6;

// Per-voxel flags of the work grid.
constexpr std::uint8_t kSurface = 1;        // a triangle crosses the voxel's interior
constexpr std::uint8_t kBlockedFace = 2;    // << axis: a triangle lies in the voxel's min face on that axis
constexpr std::uint8_t kOutside = 16;       // reached by the flood from the border

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Projections of the triangle and of the box onto `axis` are disjoint.
bool separatedOn(const Vec3& axis, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& half) {
  const double pa = axis.dot(a), pb = axis.dot(b), pc = axis.dot(c);
  const double r = half.dot(axis.cwiseAbs());
  return std::min({pa, pb, pc}) > r || std::max({pa, pb, pc}) < -r;
}

struct Grid {
  int n[3] = {0, 0, 0};
  Vec3 origin = Vec3::Zero();
  double voxel = 0.0;
  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(n[0]) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(n[1]) * k);
  }
  std::size_t size() const { return static_cast<std::size_t>(n[0]) * n[1] * n[2]; }
};

Grid sizeGrid(const MeshStats& stats, const VoxeliseOptions& options) {
  const Vec3 extent = stats.max - stats.min;
  double voxel = options.voxel_size;
  if (voxel == 0.0) {
    if (options.resolution < 1 || options.resolution > kMaxResolution) {
      throw InputError("resolution", options.source + ": must be in [1, " + std::to_string(kMaxResolution) +
                                         "], got " + std::to_string(options.resolution));
    }
    voxel = extent.maxCoeff() / options.resolution;
  }
  const VoxelLimits& limits = options.limits;
  validateVoxelSize(voxel, limits, options.source + ": ",
                    options.voxel_size == 0.0 ? " (mesh extent / resolution)" : "");
  Grid g;
  g.voxel = voxel;
  double cells = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    // One empty voxel of padding on each side: the flood starts there.
    const double inner = std::max(1.0, std::ceil(extent[axis] / voxel - kPlaneTolerance));
    cells *= inner + 2.0;
    if (inner + 2.0 > 1e9) cells = 1e30;
    g.n[axis] = static_cast<int>(std::min(inner + 2.0, 1e9));
    // Centred: the mesh's slack is shared by both sides.
    g.origin[axis] = stats.min[axis] - voxel - 0.5 * (inner * voxel - extent[axis]);
  }
  if (cells > static_cast<double>(limits.max_voxels)) {
    throw InputError("max_voxels", options.source + ": voxelising at " + number(voxel) + " m needs " +
                                       number(cells) + " voxels above max_voxels " +
                                       std::to_string(limits.max_voxels));
  }
  return g;
}

// Marks the voxels each triangle crosses, and for triangles lying in a grid
// plane the voxel faces they cover.
void markTriangles(const TriangleMesh& mesh, const Grid& g, std::vector<std::uint8_t>& flags) {
  const double a = g.voxel, eps = kPlaneTolerance * a;
  const Vec3 interior_half = Vec3::Constant(0.5 * a - eps);
  for (const auto& t : mesh.triangles) {
    const Vec3 p[3] = {(mesh.vertices[t[0]] - g.origin) / a, (mesh.vertices[t[1]] - g.origin) / a,
                       (mesh.vertices[t[2]] - g.origin) / a};
    int lo[3], hi[3];
    bool flat[3];
    for (int axis = 0; axis < 3; ++axis) {
      const double mn = std::min({p[0][axis], p[1][axis], p[2][axis]});
      const double mx = std::max({p[0][axis], p[1][axis], p[2][axis]});
      lo[axis] = std::clamp(static_cast<int>(std::floor(mn)) - 1, 0, g.n[axis] - 1);
      hi[axis] = std::clamp(static_cast<int>(std::floor(mx)) + 1, 0, g.n[axis] - 1);
      flat[axis] = mx - mn <= 2.0 * kPlaneTolerance &&
                   std::abs(mn - std::round(mn)) <= kPlaneTolerance;  // in a grid plane
    }
    const Vec3& v0 = mesh.vertices[t[0]];
    const Vec3& v1 = mesh.vertices[t[1]];
    const Vec3& v2 = mesh.vertices[t[2]];
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const Vec3 corner = g.origin + a * Vec3(i, j, k);
          std::uint8_t& f = flags[g.index(i, j, k)];
          if (!(f & kSurface) && triangleOverlapsBox(v0, v1, v2, corner + Vec3::Constant(0.5 * a), interior_half))
            f |= kSurface;
          for (int axis = 0; axis < 3; ++axis) {
            if (!flat[axis] || (f & (kBlockedFace << axis))) continue;
            Vec3 centre = corner + Vec3::Constant(0.5 * a);
            centre[axis] = corner[axis];
            Vec3 half = interior_half;
            half[axis] = eps;
            if (triangleOverlapsBox(v0, v1, v2, centre, half)) f |= static_cast<std::uint8_t>(kBlockedFace << axis);
          }
        }
  }
}

// Breadth-first flood of the outside from every border voxel, never entering a
// surface voxel nor crossing a blocked face.
void floodOutside(const Grid& g, std::vector<std::uint8_t>& flags) {
  std::vector<std::size_t> queue;
  const auto enter = [&](std::size_t v) {
    if (flags[v] & (kSurface | kOutside)) return;
    flags[v] |= kOutside;
    queue.push_back(v);
  };
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i)
        if (i == 0 || j == 0 || k == 0 || i == g.n[0] - 1 || j == g.n[1] - 1 || k == g.n[2] - 1)
          enter(g.index(i, j, k));
  const std::size_t stride[3] = {1, static_cast<std::size_t>(g.n[0]),
                                 static_cast<std::size_t>(g.n[0]) * g.n[1]};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t v = queue[head];
    std::size_t rest = v;
    int c[3];
    for (int axis = 0; axis < 3; ++axis) {
      c[axis] = static_cast<int>(rest % static_cast<std::size_t>(g.n[axis]));
      rest /= static_cast<std::size_t>(g.n[axis]);
    }
    for (int axis = 0; axis < 3; ++axis) {
      const std::uint8_t blocked = static_cast<std::uint8_t>(kBlockedFace << axis);
      if (c[axis] > 0 && !(flags[v] & blocked)) enter(v - stride[axis]);
      if (c[axis] + 1 < g.n[axis] && !(flags[v + stride[axis]] & blocked)) enter(v + stride[axis]);
    }
  }
}

}  // namespace

bool triangleOverlapsBox(const Vec3& a0, const Vec3& b0, const Vec3& c0, const Vec3& centre, const Vec3& half) {
  const Vec3 a = a0 - centre, b = b0 - centre, c = c0 - centre;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::min({a[axis], b[axis], c[axis]}) > half[axis] || std::max({a[axis], b[axis], c[axis]}) < -half[axis])
      return false;
  }
  const Vec3 edges[3] = {b - a, c - b, a - c};
  const Vec3 normal = edges[0].cross(edges[1]);
  if (normal.squaredNorm() > 0.0 && separatedOn(normal, a, b, c, half)) return false;
  for (const Vec3& e : edges) {
    for (int axis = 0; axis < 3; ++axis) {
      const Vec3 cross = Vec3::Unit(axis).cross(e);
      if (cross.squaredNorm() > 0.0 && separatedOn(cross, a, b, c, half)) return false;
    }
  }
  return true;
}

MeshStats computeMeshStats(const TriangleMesh& mesh) {
  MeshStats s;
  s.vertex_count = mesh.vertices.size();
  s.triangle_count = mesh.triangles.size();
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!mesh.vertices[v].allFinite()) {
      throw InputError("vertices", "vertex " + std::to_string(v) + " is not finite");
    }
  }
  const auto vertex_count = static_cast<std::int64_t>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (std::int32_t v : mesh.triangles[t]) {
      if (v < 0 || v >= vertex_count) {
        throw InputError("triangles", "triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) +
                                          " of " + std::to_string(vertex_count));
      }
    }
  }
  if (mesh.vertices.empty()) return s;
  s.min = s.max = mesh.vertices.front();
  for (const Vec3& v : mesh.vertices) {
    s.min = s.min.cwiseMin(v);
    s.max = s.max.cwiseMax(v);
  }

  // Weld by exact position: sort indices lexicographically, equal runs share an id.
  std::vector<std::int32_t> order(mesh.vertices.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<std::int32_t>(i);
  const auto less = [&](std::int32_t x, std::int32_t y) {
    const Vec3& p = mesh.vertices[x];
    const Vec3& q = mesh.vertices[y];
    return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::int32_t> weld(mesh.vertices.size());
  std::int32_t id = -1;
  for (std::size_t r = 0; r < order.size(); ++r) {
    if (r == 0 || mesh.vertices[order[r]] != mesh.vertices[order[r - 1]]) ++id;
    weld[order[r]] = id;
  }
  s.duplicated_vertices = mesh.vertices.size() - static_cast<std::size_t>(id + 1);

  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const std::int32_t w[3] = {weld[t[0]], weld[t[1]], weld[t[2]]};
    const Vec3& p = mesh.vertices[t[0]];
    if ((mesh.vertices[t[1]] - p).cross(mesh.vertices[t[2]] - p).squaredNorm() == 0.0) ++s.degenerate_triangles;
    for (int e = 0; e < 3; ++e) {
      const std::int32_t x = w[e], y = w[(e + 1) % 3];
      if (x != y) edges.emplace_back(std::min(x, y), std::max(x, y));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t r = 0; r < edges.size();) {
    std::size_t end = r;
    while (end < edges.size() && edges[end] == edges[r]) ++end;
    if (end - r == 1) ++s.boundary_edges;
    if (end - r > 2) ++s.non_manifold_edges;
    r = end;
  }
  return s;
}

VoxelisedMesh voxeliseMesh(const TriangleMesh& mesh, const VoxeliseOptions& options) {
  if (mesh.vertices.empty()) throw InputError("vertices", options.source + ": the mesh has no vertex");
  if (mesh.triangles.empty()) throw InputError("triangles", options.source + ": the mesh has no triangle");
  MeshStats stats;
  try {
    stats = computeMeshStats(mesh);
  } catch (const InputError& e) {
    throw InputError(e.field(), options.source + ": " + std::string(e.what()).substr(e.field().size() + 2));
  }
  const Grid g = sizeGrid(stats, options);

  std::vector<std::uint8_t> flags(g.size(), 0);
  markTriangles(mesh, g, flags);
  floodOutside(g, flags);

  // Solid = not reached; crop the grid to it.
  VoxelisedMesh out;
  out.stats = stats;
  int lo[3] = {g.n[0], g.n[1], g.n[2]}, hi[3] = {-1, -1, -1};
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j)
      for (int i = 0; i < g.n[0]; ++i) {
        const std::uint8_t f = flags[g.index(i, j, k)];
        if (f & kOutside) continue;
        if (f & kSurface) ++out.surface_voxels; else ++out.interior_voxels;
        const int c[3] = {i, j, k};
        for (int axis = 0; axis < 3; ++axis) {
          lo[axis] = std::min(lo[axis], c[axis]);
          hi[axis] = std::max(hi[axis], c[axis]);
        }
      }
  // No enclosed voxel and open edges: the outside got in (an open sheet, or a
  // hole wider than a voxel). A closed mesh thinner than a voxel has no open
  // edge and is kept as its surface voxels.
  if (out.interior_voxels == 0 && stats.boundary_edges > 0) {
    throw InputError("mesh", options.source + ": cannot be closed: the outside reaches every voxel not on the "
                             "surface (" + std::to_string(stats.boundary_edges) +
                             " open edges: an open sheet, or a hole wider than a voxel of " + number(g.voxel) + " m)");
  }
  if (hi[0] < 0) throw InputError("mesh", options.source + ": encloses no voxel");

  const int n[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
  std::vector<std::uint8_t> occupancy(static_cast<std::size_t>(n[0]) * n[1] * n[2], 0);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        occupancy[static_cast<std::size_t>(i) + static_cast<std::size_t>(n[0]) * (j + static_cast<std::size_t>(n[1]) * k)] =
            (flags[g.index(i + lo[0], j + lo[1], k + lo[2])] & kOutside) ? 0 : 1;
  out.shape = VoxelShape::create(n[0], n[1], n[2], g.voxel, std::move(occupancy), options.limits);
  out.shape.setSurfaceMargin(std::sqrt(3.0) * g.voxel);
  out.grid_origin = g.origin + g.voxel * Vec3(lo[0], lo[1], lo[2]);
  return out;
}

}  // namespace stc
