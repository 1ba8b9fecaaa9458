// Triangle meshes read from STL, OBJ or DAE files with assimp, and the shapes
// made from them, cached in a World by resource, scale and voxel size.
// Lives in the stc_mesh library, beside the core: stc_core stays Eigen-only.
#pragma once

#include "sphere_tree_collision/mesh_voxeliser.hpp"
#include "sphere_tree_collision/world.hpp"

#include <string>

namespace stc {

// The file a resource names: a plain path, or a "file://" URI. Other schemes
// ("package://" ...) are resolved by the caller (the ROS layer) first.
// Throws InputError("mesh_resource") for an empty resource or another scheme.
std::string meshResourcePath(const std::string& resource);

// Every triangle of every mesh in the file, with the scene's node transforms
// (and a DAE's unit) applied, then scaled per axis. A DAE's up axis is
// ignored: vertices stay as written, as for STL and OBJ.
// Throws InputError("scale") unless every component is finite and > 0, and
// InputError("mesh_resource") naming the file and the reason when it is not
// a regular file, assimp cannot read it, or it holds no triangle.
TriangleMesh loadTriangleMesh(const std::string& resource, const Vec3& scale = Vec3::Ones());

// "mesh:<resource>@<sx>,<sy>,<sz>/<voxel size or rN>": the World's shape key.
std::string meshShapeKey(const std::string& resource, const Vec3& scale, const VoxeliseOptions& options);

// The shape of a mesh resource: found in `world` by its key, else loaded,
// voxelised and added (its sphere-tree built once). Throws the errors of
// loadTriangleMesh and voxeliseMesh (options.source is set to the resource).
ShapeId addMeshShape(World& world, const std::string& resource, const Vec3& scale,
                     VoxeliseOptions options = VoxeliseOptions{});

}  // namespace stc
