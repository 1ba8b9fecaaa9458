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
  VoxelisedMesh voxels = voxeliseMesh(loadTriangleMesh(resource, scale, up_axis), options);
  return world.addShape(key, std::move(voxels.shape));
}

}  // namespace stc
