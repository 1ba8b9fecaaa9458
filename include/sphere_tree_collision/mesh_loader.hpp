// Triangle meshes read from STL, OBJ or DAE files with assimp, and the shapes
// made from them, cached in a World by resource, scale and voxel size.
// Lives in the stc_mesh library, beside the core: stc_core stays Eigen-only.
#pragma once

#include "sphere_tree_collision/mesh_voxeliser.hpp"
#include "sphere_tree_collision/world.hpp"

#include <cstdint>
#include <string>

namespace stc {

// The file a resource names: a plain path, or a "file://" URI. Other schemes
// ("package://" ...) are resolved by the caller (the ROS layer) first.
// Throws InputError("mesh_resource") for an empty resource or another scheme.
std::string meshResourcePath(const std::string& resource);

// What a DAE's <up_axis> (X_UP, Y_UP, Z_UP; Y_UP when absent) does.
// rviz, MoveIt (geometric_shapes) and Gazebo draw and collide a DAE's vertices
// as written, whatever its up axis: AsWritten, the default, agrees with them,
// so a shape lands where rviz draws the same mesh_resource. ToZUp follows the
// Collada convention: the file's up axis becomes +z (ROS's up), so a Y_UP
// file is turned +90 degrees about x and a Z_UP file stays as written.
// STL and OBJ have no up axis: both read them as written.
enum class ColladaUpAxis : std::uint8_t { AsWritten, ToZUp };
// "" or "as_written" | "z_up"; throws InputError("up_axis").
ColladaUpAxis parseColladaUpAxis(const std::string& name);

// Every triangle of every mesh in the file, with the scene's node transforms
// (and a DAE's unit and, by `up_axis`, its up axis) applied, then scaled per
// axis. A file is a DAE by its extension (.dae, any case).
// Throws InputError("scale") unless every component is finite and > 0, and
// InputError("mesh_resource") naming the file and the reason when it is not
// a regular file, assimp cannot read it, or it holds no triangle.
TriangleMesh loadTriangleMesh(const std::string& resource, const Vec3& scale = Vec3::Ones(),
                              ColladaUpAxis up_axis = ColladaUpAxis::AsWritten);

// "mesh:<resource>@<sx>,<sy>,<sz>/<voxel size or rN>[/z_up]": the World's shape key.
std::string meshShapeKey(const std::string& resource, const Vec3& scale, const VoxeliseOptions& options,
                         ColladaUpAxis up_axis = ColladaUpAxis::AsWritten);

// The shape of a mesh resource: found in `world` by its key, else loaded,
// voxelised and added (its sphere-tree built once). Throws the errors of
// loadTriangleMesh and voxeliseMesh (options.source is set to the resource).
ShapeId addMeshShape(World& world, const std::string& resource, const Vec3& scale,
                     VoxeliseOptions options = VoxeliseOptions{},
                     ColladaUpAxis up_axis = ColladaUpAxis::AsWritten);

}  // namespace stc
