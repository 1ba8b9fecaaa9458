// Fracture (issue 14): a body whose contact impulse in a tick exceeds its
// material strength splits along a plane through the impact point into the
// connected voxel components on either side (docs/fracture.md). Here the pure
// part, on a VoxelShape in its grid frame; World::breakEntity places the pieces.
#pragma once

#include "sphere_tree_collision/phase_options.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace stc {

// The strength of a piece of `piece_voxels` cut from a body of
// `parent_voxels` whose strength is `parent_strength`: the impulse that
// breaks a body grows as its volume to the power `exponent`.
double pieceStrength(double parent_strength, std::int64_t piece_voxels, std::int64_t parent_voxels,
                     double exponent);

// What a new piece's sphere-tree costs, learned from the trees built:
// seconds per voxel, the largest of recent builds (each build forgets 10 % of
// the older maximum, so a slow moment is not assumed for ever). Unknown (infinite)
// until one build is measured, so the first tree is never guessed to fit.
class TreeCostEstimate {
 public:
  double seconds(std::int64_t voxels) const;  // infinity while unknown
  void record(std::int64_t voxels, double seconds);

 private:
  double seconds_per_voxel_ = -1.0;  // < 0: unknown
};

// A plane in a shape's grid frame; the normal is unit.
struct SplitPlane {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();
};

// The fracture plane of an impact at `point` along the contact normal `normal`
// on a body whose centre of mass is `centre` (one frame): the plane holds the
// contact normal and passes through the impact point and the centre, as a
// disc loaded across a diameter splits along that diameter (the Brazilian
// test). When the impact is head-on (the centre on the normal's line) the
// plane's turn about the normal is the first of tangentBasis(normal).
SplitPlane fracturePlane(const Vec3& point, const Vec3& normal, const Vec3& centre);

// One piece of a split shape: a tight grid whose voxel (0,0,0) is the
// parent's voxel `offset`, so it sits exactly where it was in the parent.
struct VoxelPiece {
  VoxelShape shape;
  Eigen::Vector3i offset = Eigen::Vector3i::Zero();
  std::int64_t voxels = 0;
};

// Component label of every cell (-1 empty): occupied face neighbours
// (6-connectivity) on the same side of the plane share one. A voxel is on the
// side of its centre; a centre on the plane counts as the + side. Sets *count.
std::vector<std::int32_t> labelSplitComponents(const VoxelShape& shape, const SplitPlane& plane,
                                               int* count);

// The components as pieces, largest first (ties: lowest first voxel). Those
// under options.min_piece_voxels join the largest (Attach) or are dropped
// (Vanish). One piece with all the voxels means the plane split nothing.
std::vector<VoxelPiece> splitVoxelShape(const VoxelShape& shape, const SplitPlane& plane,
                                        const FractureOptions& options);

// A World shape key from the piece's content (dims, voxel size, occupancy):
// equal pieces, from any parent, share one sphere-tree.
std::string pieceShapeKey(const VoxelShape& shape);
// Same dims, voxel size and occupancy.
bool sameVoxels(const VoxelShape& a, const VoxelShape& b);

}  // namespace stc
