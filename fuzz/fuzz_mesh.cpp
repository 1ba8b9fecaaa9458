// Fuzz target: the bytes of a mesh file (what a spawn's mesh_resource makes
// the node read: STL ASCII or binary, OBJ, DAE, parsed by assimp) through
// parseTriangleMesh and the voxeliser. The first byte picks the format, the
// DAE up axis and the resolution; the rest is the file. Nothing but these
// bytes is read: parseTriangleMesh gives assimp no file system. Only
// stc::InputError may come out, and a mesh that loads keeps to the limits.
#include "fuzz_support.hpp"
#include "sphere_tree_collision/mesh_loader.hpp"

#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* const kFormats[] = {"stl", "obj", "dae"};
  const unsigned head = data[0];
  const std::string format = kFormats[head % 3];
  const auto up_axis = (head / 3) % 2 == 0 ? stc::ColladaUpAxis::AsWritten : stc::ColladaUpAxis::ToZUp;
  // Small limits: one input runs in milliseconds, and inputs reach them.
  stc::MeshLimits limits;
  limits.max_mesh_bytes = 1 << 20;
  limits.max_mesh_vertices = 30000;
  limits.max_mesh_triangles = 10000;
  stc::VoxeliseOptions options;
  options.resolution = 1 + static_cast<int>((head / 6) % 32);
  options.limits = stc_fuzz::smallWorldConfig().voxel_limits;
  options.source = "fuzz." + format;
  try {
    const stc::TriangleMesh mesh =
        stc::parseTriangleMesh(data + 1, size - 1, format, options.source, stc::Vec3::Ones(), up_axis, limits);
    stc_fuzz::require(!mesh.triangles.empty(), "a mesh loaded with no triangle");
    stc_fuzz::require(static_cast<std::int64_t>(mesh.vertices.size()) <= limits.max_mesh_vertices,
                      "more vertices than max_mesh_vertices");
    stc_fuzz::require(static_cast<std::int64_t>(mesh.triangles.size()) <= limits.max_mesh_triangles,
                      "more triangles than max_mesh_triangles");
    const stc::VoxelisedMesh voxels = stc::voxeliseMesh(mesh, options);
    const stc::VoxelShape& shape = voxels.shape;
    stc_fuzz::require(static_cast<double>(shape.nx()) * shape.ny() * shape.nz() <=
                          static_cast<double>(options.limits.max_voxels),
                      "a grid above max_voxels");
    stc_fuzz::require(shape.occupiedCount() > 0, "a voxelised mesh with no voxel");
  } catch (const stc::InputError&) {
    return 0;
  }
  return 0;
}
