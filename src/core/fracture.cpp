// Fracture geometry: split a voxel grid by a plane into connected pieces.
#include "fracture.hpp"

#include "contact_solver.hpp"  // tangentBasis

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>

namespace stc {
namespace {

// |n x (c - p)| below this share of |c - p| counts as a head-on impact.
constexpr double kHeadOnTolerance = 1e-6;

}  // namespace

SmallPieces parseSmallPieces(const std::string& name) {
  if (name == "attach") return SmallPieces::Attach;
  if (name == "vanish") return SmallPieces::Vanish;
  throw InputError("fracture.small_pieces", "'" + name + "' is not one of attach, vanish");
}

void validateFractureOptions(const FractureOptions& options) {
  if (options.min_piece_voxels < 1) {
    throw InputError("fracture.min_piece_voxels",
                     "must be >= 1, got " + std::to_string(options.min_piece_voxels));
  }
  if (options.small_pieces != SmallPieces::Attach && options.small_pieces != SmallPieces::Vanish) {
    throw InputError("fracture.small_pieces", "must be attach or vanish");
  }
  if (!(std::isfinite(options.strength_exponent) && options.strength_exponent >= 0.0)) {
    throw InputError("fracture.strength_exponent", "must be finite and >= 0");
  }
}

double pieceStrength(double parent_strength, std::int64_t piece_voxels, std::int64_t parent_voxels,
                     double exponent) {
  if (exponent == 0.0 || parent_voxels <= 0) return parent_strength;
  return parent_strength * std::pow(static_cast<double>(piece_voxels) / static_cast<double>(parent_voxels), exponent);
}

double TreeCostEstimate::seconds(std::int64_t voxels) const {
  if (seconds_per_voxel_ < 0.0) return std::numeric_limits<double>::infinity();
  return seconds_per_voxel_ * static_cast<double>(voxels);
}

void TreeCostEstimate::record(std::int64_t voxels, double seconds) {
  constexpr double kForget = 0.9;
  const double rate = seconds / static_cast<double>(std::max<std::int64_t>(voxels, 1));
  if (!(rate >= 0.0)) return;  // a clock that went back tells nothing
  seconds_per_voxel_ = seconds_per_voxel_ < 0.0 ? rate : std::max(rate, kForget * seconds_per_voxel_);
}

SplitPlane fracturePlane(const Vec3& point, const Vec3& normal, const Vec3& centre) {
  const Vec3 n = normal.normalized();
  const Vec3 to_centre = centre - point;
  Vec3 m = n.cross(to_centre);
  if (!(m.norm() > kHeadOnTolerance * to_centre.norm())) {
    Vec3 t2;
    tangentBasis(n, m, t2);
  }
  return SplitPlane{point, m.normalized()};
}

std::vector<std::int32_t> labelSplitComponents(const VoxelShape& shape, const SplitPlane& plane,
                                               int* count) {
  const int nx = shape.nx(), ny = shape.ny(), nz = shape.nz();
  const double s = shape.voxelSize();
  std::vector<std::int32_t> label(shape.occupancy().size(), -1);
  // Side of each voxel's centre: the plane cuts between voxels, never through one.
  std::vector<std::uint8_t> side(label.size(), 0);
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const Vec3 centre = (Vec3(i, j, k) + Vec3::Constant(0.5)) * s;
        side[shape.index(i, j, k)] = plane.normal.dot(centre - plane.point) >= 0.0 ? 1 : 0;
      }
    }
  }
  int components = 0;
  std::vector<Eigen::Vector3i> stack;
  static const int kSteps[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const std::size_t seed = shape.index(i, j, k);
        if (!shape.occupied(i, j, k) || label[seed] >= 0) continue;
        label[seed] = components;
        stack.assign(1, Eigen::Vector3i(i, j, k));
        while (!stack.empty()) {  // flood fill with an explicit stack: no recursion depth limit
          const Eigen::Vector3i v = stack.back();
          stack.pop_back();
          for (const auto& step : kSteps) {
            const Eigen::Vector3i w = v + Eigen::Vector3i(step[0], step[1], step[2]);
            if (!shape.occupied(w.x(), w.y(), w.z())) continue;
            const std::size_t at = shape.index(w.x(), w.y(), w.z());
            if (label[at] >= 0 || side[at] != side[seed]) continue;
            label[at] = components;
            stack.push_back(w);
          }
        }
        ++components;
      }
    }
  }
  *count = components;
  return label;
}

std::vector<VoxelPiece> splitVoxelShape(const VoxelShape& shape, const SplitPlane& plane,
                                        const FractureOptions& options) {
  int count = 0;
  const std::vector<std::int32_t> label = labelSplitComponents(shape, plane, &count);
  std::vector<std::int64_t> size(count, 0);
  for (const std::int32_t l : label) {
    if (l >= 0) ++size[l];
  }
  // Labels are numbered in scan order, so the stable sort breaks ties by first voxel.
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return size[a] > size[b]; });

  // Which piece each component goes to (-1: vanishes).
  std::vector<int> piece_of(count, -1);
  int pieces = 0;
  for (const int c : order) {
    if (pieces == 0 || size[c] >= options.min_piece_voxels) {
      piece_of[c] = pieces++;
    } else if (options.small_pieces == SmallPieces::Attach) {
      piece_of[c] = 0;
    }
  }

  // Tight bounds of each piece's voxels.
  std::vector<Eigen::Vector3i> lo(pieces, Eigen::Vector3i(shape.nx(), shape.ny(), shape.nz()));
  std::vector<Eigen::Vector3i> hi(pieces, Eigen::Vector3i(-1, -1, -1));
  // Calls visit(piece, cell) for every voxel that went to a piece.
  const auto forEachPieceVoxel = [&](const auto& visit) {
    for (int k = 0; k < shape.nz(); ++k) {
      for (int j = 0; j < shape.ny(); ++j) {
        for (int i = 0; i < shape.nx(); ++i) {
          const std::int32_t l = label[shape.index(i, j, k)];
          if (l >= 0 && piece_of[l] >= 0) visit(piece_of[l], Eigen::Vector3i(i, j, k));
        }
      }
    }
  };
  forEachPieceVoxel([&](int p, const Eigen::Vector3i& cell) {
    lo[p] = lo[p].cwiseMin(cell);
    hi[p] = hi[p].cwiseMax(cell);
  });
  std::vector<std::vector<std::uint8_t>> grids(pieces);
  for (int p = 0; p < pieces; ++p) {
    const Eigen::Vector3i dims = hi[p] - lo[p] + Eigen::Vector3i::Ones();
    grids[p].assign(static_cast<std::size_t>(dims.x()) * dims.y() * dims.z(), 0);
  }
  forEachPieceVoxel([&](int p, const Eigen::Vector3i& cell) {
    const Eigen::Vector3i dims = hi[p] - lo[p] + Eigen::Vector3i::Ones();
    const Eigen::Vector3i v = cell - lo[p];
    grids[p][static_cast<std::size_t>(v.x()) +
             static_cast<std::size_t>(dims.x()) * (static_cast<std::size_t>(v.y()) +
                                                   static_cast<std::size_t>(dims.y()) * v.z())] = 1;
  });
  // A piece is never larger than its parent: the parent's grid and voxel size are its limits.
  VoxelLimits limits;
  limits.max_voxels = static_cast<std::int64_t>(shape.occupancy().size());
  limits.min_voxel_size = limits.max_voxel_size = shape.voxelSize();
  std::vector<VoxelPiece> result;
  result.reserve(pieces);
  for (int p = 0; p < pieces; ++p) {
    const Eigen::Vector3i dims = hi[p] - lo[p] + Eigen::Vector3i::Ones();
    VoxelPiece piece{VoxelShape::create(dims.x(), dims.y(), dims.z(), shape.voxelSize(),
                                        std::move(grids[p]), limits),
                     lo[p], 0};
    piece.voxels = piece.shape.occupiedCount();
    result.push_back(std::move(piece));
  }
  return result;
}

std::string pieceShapeKey(const VoxelShape& shape) {
  // FNV-1a over the occupancy; the dims, voxel size and count make a clash
  // between different pieces even less likely, and World::breakEntity checks.
  std::uint64_t hash = 1469598103934665603ull;
  for (const std::uint8_t cell : shape.occupancy()) {
    hash = (hash ^ cell) * 1099511628211ull;
  }
  char text[160];
  std::snprintf(text, sizeof(text), "piece/%dx%dx%d@%.17g/%lld/%016llx", shape.nx(), shape.ny(), shape.nz(),
                shape.voxelSize(), static_cast<long long>(shape.occupiedCount()),
                static_cast<unsigned long long>(hash));
  return text;
}

bool sameVoxels(const VoxelShape& a, const VoxelShape& b) {
  return a.nx() == b.nx() && a.ny() == b.ny() && a.nz() == b.nz() && a.voxelSize() == b.voxelSize() &&
         a.occupancy() == b.occupancy();
}

}  // namespace stc
