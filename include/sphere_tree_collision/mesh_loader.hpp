// Triangle meshes read from STL, OBJ or DAE files with assimp, and the shapes
// made from them, cached in a World by resource, scale and voxel size.
// Lives in the stc_mesh library, beside the core: stc_core stays Eigen-only.
#pragma once

#include "sphere_tree_collision/mesh_voxeliser.hpp"
#include "sphere_tree_collision/world.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace stc {

// The file a resource names: a plain path, or a "file://" URI. Other schemes
// ("package://" ...) are resolved by the caller (the ROS layer) first.
// Throws InputError("mesh_resource") for an empty resource or another scheme.
std::string meshResourcePath(const std::string& resource);

// "stl", "obj" or "dae" by the path's extension (any case); throws
// InputError("mesh_resource"), naming `source`, for any other: only these
// three formats are handed to assimp.
std::string meshFormatOf(const std::string& path, const std::string& source);

// The folders meshes may be read from, canonical (symlinks resolved). Throws
// InputError("<field>[i]") for an entry that is not an absolute path to an
// existing folder.
std::vector<std::string> canonicalMeshRoots(const std::vector<std::string>& roots,
                                            const std::string& field = "mesh_roots");

// The canonical path of a plain path or file:// resource (`..` and symlinks
// resolved, so neither leads out) when it names an existing file under one of
// `roots` (canonical, as canonicalMeshRoots gives them). Throws
// InputError("mesh_resource") otherwise, naming the resource as given, with
// the same words for a missing file and one outside the roots.
std::string meshPathWithinRoots(const std::string& resource, const std::vector<std::string>& roots);

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

// Every triangle of every mesh in a file's bytes (`format` "stl", "obj" or
// "dae"), with the scene's node transforms (and a DAE's unit and, by
// `up_axis`, its up axis) applied, then scaled per axis. The bytes are
// untrusted: assimp opens no other file (an OBJ's mtllib is not read), and
// vertices and triangles are counted against `limits` before they are copied.
// Throws InputError("scale") unless every component is finite and > 0, and
// InputError("mesh_resource") naming `source` and the reason (a limit as
// "<n> triangles above max_mesh_triangles <limit>"; max_mesh_bytes,
// max_mesh_vertices likewise) when the format is not
// one of the three, assimp cannot read the bytes, a face names a vertex its
// mesh lacks, or no triangle is left.
TriangleMesh parseTriangleMesh(const void* bytes, std::size_t size, const std::string& format,
                               const std::string& source, const Vec3& scale = Vec3::Ones(),
                               ColladaUpAxis up_axis = ColladaUpAxis::AsWritten,
                               const MeshLimits& limits = MeshLimits{});

// The file a resource names (meshResourcePath; no roots are checked here:
// the ROS layer does it, meshPathWithinRoots), parsed by parseTriangleMesh.
// Its format is its extension (.stl, .obj, .dae, any case). Throws the errors
// of parseTriangleMesh, and InputError("mesh_resource") when the file is not
// a regular file or is larger than limits.max_mesh_bytes (checked before it
// is read).
TriangleMesh loadTriangleMesh(const std::string& resource, const Vec3& scale = Vec3::Ones(),
                              ColladaUpAxis up_axis = ColladaUpAxis::AsWritten,
                              const MeshLimits& limits = MeshLimits{});

// "mesh:<resource>@<sx>,<sy>,<sz>/<voxel size or rN>[/z_up]": the World's shape key.
std::string meshShapeKey(const std::string& resource, const Vec3& scale, const VoxeliseOptions& options,
                         ColladaUpAxis up_axis = ColladaUpAxis::AsWritten);

// The shape of a mesh resource: found in `world` by its key, else loaded
// (within world.config().mesh_limits), voxelised and added (its sphere-tree
// built once). Throws the errors of loadTriangleMesh and voxeliseMesh
// (options.source is set to the resource), but a grid above options.limits'
// max_voxels as InputError("mesh_resource"): "... voxels above max_voxels <limit>".
ShapeId addMeshShape(World& world, const std::string& resource, const Vec3& scale,
                     VoxeliseOptions options = VoxeliseOptions{},
                     ColladaUpAxis up_axis = ColladaUpAxis::AsWritten);

}  // namespace stc
