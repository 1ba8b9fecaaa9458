// assimp -> TriangleMesh: one flat vertex array for all the file's meshes.
#include "sphere_tree_collision/mesh_loader.hpp"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace stc {
namespace {

const std::string kFileScheme = "file://";

bool isDae(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".dae";
}

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace

ColladaUpAxis parseColladaUpAxis(const std::string& name) {
  if (name.empty() || name == "as_written") return ColladaUpAxis::AsWritten;
  if (name == "z_up") return ColladaUpAxis::ToZUp;
  throw InputError("up_axis", "'" + name + "' is not one of as_written, z_up");
}

std::string meshResourcePath(const std::string& resource) {
  if (resource.empty()) throw InputError("mesh_resource", "is empty");
  if (resource.compare(0, kFileScheme.size(), kFileScheme) == 0) return resource.substr(kFileScheme.size());
  const std::size_t scheme = resource.find("://");
  if (scheme != std::string::npos) {
    throw InputError("mesh_resource", resource + ": scheme '" + resource.substr(0, scheme) +
                                          "://' is not a file; resolve it first (package:// in the ROS node)");
  }
  return resource;
}

TriangleMesh loadTriangleMesh(const std::string& resource, const Vec3& scale, ColladaUpAxis up_axis) {
  if (!scale.allFinite() || !(scale.minCoeff() > 0.0)) {
    throw InputError("scale", "every component must be finite and > 0, got (" + number(scale.x()) + ", " +
                                  number(scale.y()) + ", " + number(scale.z()) + ")");
  }
  const std::string path = meshResourcePath(resource);
  // Devices, pipes and directories are refused before assimp opens them (a
  // read of /dev/stdin would block).
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError("mesh_resource", resource + ": not a regular file");
  }
  Assimp::Importer importer;
  // assimp turns a DAE whose up axis is not Y_UP so that it is (its root
  // node's transform), unless told to ignore the up axis; the unit is
  // applied either way.
  const bool to_z_up = up_axis == ColladaUpAxis::ToZUp && isDae(path);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, !to_z_up);
  // No welding or normal fixing: the voxeliser copes with duplicated vertices
  // and reports them; node transforms are baked into the vertices.
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    throw InputError("mesh_resource", resource + ": cannot be read: " + importer.GetErrorString());
  }
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& in = *scene->mMeshes[m];
    const auto base = static_cast<std::int32_t>(mesh.vertices.size());
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiVector3D& p = in.mVertices[v];
      // assimp's y up to ROS's z up: +90 degrees about x.
      const Vec3 vertex = to_z_up ? Vec3(p.x, -p.z, p.y) : Vec3(p.x, p.y, p.z);
      mesh.vertices.push_back(vertex.cwiseProduct(scale));
    }
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      const aiFace& face = in.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines enclose nothing
      mesh.triangles.push_back({base + static_cast<std::int32_t>(face.mIndices[0]),
                                base + static_cast<std::int32_t>(face.mIndices[1]),
                                base + static_cast<std::int32_t>(face.mIndices[2])});
    }
  }
  if (mesh.triangles.empty()) throw InputError("mesh_resource", resource + ": holds no triangle");
  return mesh;
}

}  // namespace stc
