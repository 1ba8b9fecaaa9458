// Exact Euclidean distance transform of a voxel grid with the nearest cell
// kept (Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled
// Functions", 2012: lower envelopes of parabolas, row by row, axis by axis),
// measured from a cell's centre to the nearest point of the other cell's box.
#include "interior_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {
namespace {

constexpr double kFar = std::numeric_limits<double>::infinity();

// One row: d[q] = min over p of (q - p - shift)^2 + f[p], and at[q] that p
// (-1 when every f is infinite): the lower envelope of parabolas centred at
// p + shift. v, z: scratch of n and n + 1 entries.
void envelope(const double* f, int n, double shift, double* d, std::int32_t* at, std::int32_t* v, double* z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kFar) continue;
    const double sq = q + shift;
    const double fq = f[q] + sq * sq;
    double s = -kFar;
    while (k >= 0) {
      const double sp = v[k] + shift;
      s = (fq - (f[v[k]] + sp * sp)) / (2.0 * (sq - sp));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kFar : s;
    z[k + 1] = kFar;
  }
  if (k < 0) {
    std::fill(d, d + n, kFar);
    std::fill(at, at + n, -1);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double off = q - (v[j] + shift);
    d[q] = off * off + f[v[j]];
    at[q] = v[j];
  }
}

// Scratch of one row.
struct Row {
  explicit Row(int n) : f(n), d(n), d2(n), z(n + 1), at(n), at2(n), v(n) {}
  std::vector<double> f, d, d2, z;
  std::vector<std::int32_t> at, at2, v;
};

// One row in the voxels' own distance: from the centre of cell q to the cell
// p is max(|q - p| - 1/2, 0) along the row (to the nearest point of its box).
// Beside q, p lies half a cell nearer than its centre: two envelopes, of the
// cells below q (centres moved up half a cell) and above it (moved down).
void boxEnvelope(int n, Row& r) {
  envelope(r.f.data(), n, 0.5, r.d.data(), r.at.data(), r.v.data(), r.z.data());
  envelope(r.f.data(), n, -0.5, r.d2.data(), r.at2.data(), r.v.data(), r.z.data());
  for (int q = 0; q < n; ++q) {
    // Each envelope overstates the other side's cells, never understates: the min is exact.
    if (r.d2[q] < r.d[q]) {
      r.d[q] = r.d2[q];
      r.at[q] = r.at2[q];
    }
    if (r.f[q] <= r.d[q]) {  // the cell itself (distance 0 along the row)
      r.d[q] = r.f[q];
      r.at[q] = r.f[q] == kFar ? r.at[q] : q;
    }
  }
}

// For every cell of an nx x ny x nz grid (x fastest), the linear index of the
// nearest cell with site[cell] set (-1 when there is none).
std::vector<std::int32_t> nearestSites(const std::vector<std::uint8_t>& site, int nx, int ny, int nz) {
  const std::size_t count = site.size();
  std::vector<double> dist(count);
  std::vector<std::int32_t> sx(count), sy(count, 0), sz(count, 0);
  Row r(std::max({nx, ny, nz}));
  const auto index = [&](int i, int j, int k) {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (static_cast<std::size_t>(j) +
                                                                         static_cast<std::size_t>(ny) * k);
  };
  // Along x: the nearest site of the row.
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) r.f[i] = site[index(i, j, k)] != 0 ? 0.0 : kFar;
      boxEnvelope(nx, r);
      for (int i = 0; i < nx; ++i) {
        dist[index(i, j, k)] = r.d[i];
        sx[index(i, j, k)] = r.at[i];
      }
    }
  }
  // Along y, then z: the nearest of the rows' nearest, carrying its coordinates.
  std::vector<std::int32_t> cx(r.f.size()), cy(r.f.size());
  for (int k = 0; k < nz; ++k) {
    for (int i = 0; i < nx; ++i) {
      for (int j = 0; j < ny; ++j) {
        r.f[j] = dist[index(i, j, k)];
        cx[j] = sx[index(i, j, k)];
      }
      boxEnvelope(ny, r);
      for (int j = 0; j < ny; ++j) {
        const std::size_t c = index(i, j, k);
        dist[c] = r.d[j];
        sx[c] = r.at[j] < 0 ? -1 : cx[r.at[j]];
        sy[c] = r.at[j];
      }
    }
  }
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      for (int k = 0; k < nz; ++k) {
        r.f[k] = dist[index(i, j, k)];
        cx[k] = sx[index(i, j, k)];
        cy[k] = sy[index(i, j, k)];
      }
      boxEnvelope(nz, r);
      for (int k = 0; k < nz; ++k) {
        const std::size_t c = index(i, j, k);
        sx[c] = r.at[k] < 0 ? -1 : cx[r.at[k]];
        sy[c] = r.at[k] < 0 ? -1 : cy[r.at[k]];
        sz[c] = r.at[k];
      }
    }
  }
  std::vector<std::int32_t> nearest(count, -1);
  for (std::size_t c = 0; c < count; ++c) {
    if (sx[c] >= 0 && sy[c] >= 0 && sz[c] >= 0) nearest[c] = static_cast<std::int32_t>(index(sx[c], sy[c], sz[c]));
  }
  return nearest;
}

// Closest point of the unit cell at `cell` (padded grid units) to `g`.
Vec3 closestInCell(const Vec3& g, const Eigen::Vector3i& cell) {
  Vec3 q;
  for (int a = 0; a < 3; ++a) q[a] = std::clamp(g[a], double(cell[a]), double(cell[a] + 1));
  return q;
}

}  // namespace

InteriorField::InteriorField(const VoxelShape& voxels, const Vec3& body_origin)
    : px_(voxels.nx() + 2), py_(voxels.ny() + 2), pz_(voxels.nz() + 2), voxel_(voxels.voxelSize()) {
  corner_ = -body_origin - Vec3::Constant(voxel_);
  if (std::int64_t{px_} * py_ * pz_ > kMaxCells) return;
  solid_.assign(static_cast<std::size_t>(px_) * py_ * pz_, 0);
  for (int k = 0; k < voxels.nz(); ++k) {
    for (int j = 0; j < voxels.ny(); ++j) {
      for (int i = 0; i < voxels.nx(); ++i) {
        if (voxels.occupied(i, j, k)) solid_[cellIndex(i + 1, j + 1, k + 1)] = 1;
      }
    }
  }
  std::vector<std::uint8_t> empty(solid_.size());
  for (std::size_t c = 0; c < solid_.size(); ++c) empty[c] = solid_[c] != 0 ? 0 : 1;
  nearest_ = nearestSites(empty, px_, py_, pz_);             // for the occupied cells
  const std::vector<std::int32_t> to_solid = nearestSites(solid_, px_, py_, pz_);  // for the empty ones
  for (std::size_t c = 0; c < solid_.size(); ++c) {
    if (solid_[c] == 0) nearest_[c] = to_solid[c];
  }
}

InteriorProbe InteriorField::probe(const Vec3& point_body) const {
  InteriorProbe result;
  if (nearest_.empty()) return result;
  const Vec3 g = (point_body - corner_) / voxel_;  // padded grid units
  const Vec3 size(px_, py_, pz_);
  if (!(g.array() >= 1.0).all() || !(g.array() < size.array() - 1.0).all()) {
    // Outside the grid (or NaN): at least as far as the grid's box.
    const Vec3 beyond = (Vec3::Ones() - g).cwiseMax(g - (size - Vec3::Ones())).cwiseMax(0.0);
    result.depth = -beyond.norm() * voxel_;
    return result;
  }
  const Eigen::Vector3i cell = g.cast<int>();
  const std::size_t c = cellIndex(cell.x(), cell.y(), cell.z());
  const bool solid = solid_[c] != 0;
  // The nearest cell of the other kind to the cell's centre need not be the
  // nearest to the point: that of a face neighbour (or the neighbour itself)
  // may be nearer. Of these seven, the nearest box.
  double best = kFar;
  Vec3 best_to = Vec3::Zero();
  Eigen::Vector3i best_at(-1, -1, -1);  // the nearest site's cell
  const auto consider = [&](std::int32_t site) {
    if (site < 0) return;
    const Eigen::Vector3i at(site % px_, (site / px_) % py_, site / (px_ * py_));
    const Vec3 to = closestInCell(g, at) - g;
    const double d = to.squaredNorm();
    if (d < best) {
      best = d;
      best_to = to;
      best_at = at;
    }
  };
  consider(nearest_[c]);
  for (int axis = 0; axis < 3; ++axis) {
    for (int step = -1; step <= 1; step += 2) {
      Eigen::Vector3i next = cell;
      next[axis] += step;
      if (next[axis] < 0 || next[axis] >= (axis == 0 ? px_ : axis == 1 ? py_ : pz_)) continue;
      const std::size_t n = cellIndex(next.x(), next.y(), next.z());
      consider((solid_[n] != 0) == solid ? nearest_[n] : static_cast<std::int32_t>(n));
    }
  }
  if (best_at.x() < 0) return result;
  const double length = std::sqrt(best);
  if (!solid) {
    result.depth = -length * voxel_;
    return result;
  }
  result.inside = true;
  result.depth = length * voxel_;
  // On the face itself: towards the empty cell's centre.
  result.out = length > 1e-9 ? Vec3(best_to / length)
                             : Vec3((best_at.cast<double>() + Vec3::Constant(0.5) - g).normalized());
  return result;
}

}  // namespace stc
