// Mesh resources as World shapes, keyed so each (resource, scale, voxel size)
// is loaded, voxelised and given a tree once.
#include "sphere_tree_collision/mesh_loader.hpp"

#include <sstream>

namespace stc {

std::string meshShapeKey(const std::string& resource, const Vec3& scale, const VoxeliseOptions& options,
                         ColladaUpAxis up_axis) {
  std::ostringstream key;
  key.precision(17);
  key << "mesh:" << resource << '@' << scale.x() << ',' << scale.y() << ',' << scale.z() << '/';
  if (options.voxel_size > 0.0) {
    key << options.voxel_size;
  } else {
    key << 'r' << options.resolution;
  }
  if (up_axis == ColladaUpAxis::ToZUp) key << "/z_up";
  return key.str();
}

ShapeId addMeshShape(World& world, const std::string& resource, const Vec3& scale, VoxeliseOptions options,
                     ColladaUpAxis up_axis) {
  const std::string key = meshShapeKey(resource, scale, options, up_axis);
  if (const auto found = world.findShape(key)) return *found;
  options.source = resource;
  const TriangleMesh mesh = loadTriangleMesh(resource, scale, up_axis, world.config().mesh_limits);
  VoxelisedMesh voxels;
  try {
    voxels = voxeliseMesh(mesh, options);
  } catch (const InputError& e) {
    // The file's grid, not a field of the request, is too large: named as the
    // other limits of a mesh file are.
    if (e.field() != "max_voxels") throw;
    throw InputError("mesh_resource", std::string(e.what()).substr(e.field().size() + 2));
  }
  return world.addShape(key, std::move(voxels.shape));
}

}  // namespace stc
