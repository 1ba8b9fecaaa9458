// Triangle meshes turned into solid VoxelShapes (issue 14): surface voxels by
// triangle-box overlap, interior by flooding the outside from the grid border.
// Plain C++17 + Eigen; loading files is mesh_loader.hpp's job (assimp).
#pragma once

#include "sphere_tree_collision/voxel_shape.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace stc {

struct TriangleMesh {
  std::vector<Vec3> vertices;  // mesh units (metres after scaling)
  std::vector<std::array<std::int32_t, 3>> triangles;
};

// What a mesh looks like before voxelisation. Edges are counted on vertices
// welded by exact position, so duplicated vertices do not open the mesh.
struct MeshStats {
  std::size_t vertex_count = 0;
  std::size_t triangle_count = 0;
  std::size_t duplicated_vertices = 0;   // vertices at the position of an earlier one
  std::size_t degenerate_triangles = 0;  // zero area
  std::size_t boundary_edges = 0;        // used by one triangle: a hole's rim or an open sheet
  std::size_t non_manifold_edges = 0;    // used by more than two triangles
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
};

// Throws InputError("vertices") for a non-finite vertex and
// InputError("triangles") for an index outside the vertex array.
MeshStats computeMeshStats(const TriangleMesh& mesh);

struct VoxeliseOptions {
  double voxel_size = 0.0;  // metres; when 0, `resolution` decides
  int resolution = 32;      // voxels along the mesh's longest side (1..1024)
  std::string source = "mesh";  // file or resource named in error messages
  VoxelLimits limits;
};

struct VoxelisedMesh {
  VoxelShape shape;
  Vec3 grid_origin = Vec3::Zero();  // mesh coordinates of the grid's min corner
  MeshStats stats;
  std::int64_t surface_voxels = 0;   // a triangle overlaps them
  std::int64_t interior_voxels = 0;  // enclosed, no triangle in them
};

// Solid voxelisation, conservative: every voxel whose interior a triangle
// crosses is solid, so the mesh lies inside the voxels; a voxel the outside
// cannot reach without crossing a triangle is solid too. Holes and cracks
// narrower than a voxel are bridged by the surface voxels around them.
// The shape's surfaceMargin() is set to the voxel diagonal: no point of the
// voxels is farther than that from the mesh's solid.
// Throws InputError naming the field: "vertices" (none, or not finite),
// "triangles" (none, or an index out of range), "voxel_size" (not finite,
// <= 0, or outside limits), "resolution" (outside 1..1024), "max_voxels"
// (grid above limits.max_voxels), and "mesh" when the mesh encloses no volume
// (an open sheet, or a hole wider than a voxel), the message naming
// options.source and the reason.
VoxelisedMesh voxeliseMesh(const TriangleMesh& mesh, const VoxeliseOptions& options = VoxeliseOptions{});

// Whether the triangle (a, b, c) meets the axis-aligned box centre +- half
// (separating axis test: box axes, triangle normal, nine edge cross products).
bool triangleOverlapsBox(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& centre, const Vec3& half);

}  // namespace stc
