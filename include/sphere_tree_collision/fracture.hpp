// Fracture (issue 14): a body whose contact impulse in a tick exceeds its
// material strength splits along a plane through the impact point into the
// connected voxel components on either side (docs/fracture.md). Here the pure
// part, on a VoxelShape in its grid frame; World::breakEntity places the pieces.
#pragma once

#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace stc {

// What happens to the components smaller than FractureOptions::min_piece_voxels.
enum class SmallPieces : std::uint8_t {
  Attach,  // they stay with the largest piece (mass and momentum kept)
  Vanish,  // they are dropped, as dust (their mass and momentum leave the world)
};
// "attach" | "vanish"; throws InputError("fracture.small_pieces").
SmallPieces parseSmallPieces(const std::string& name);

struct FractureOptions {
  int min_piece_voxels = 8;  // >= 1; the largest piece is kept whatever its size
  SmallPieces small_pieces = SmallPieces::Attach;
};
// Throws InputError("fracture.min_piece_voxels") (< 1) or
// InputError("fracture.small_pieces") (not a known value).
void validateFractureOptions(const FractureOptions& options);

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
