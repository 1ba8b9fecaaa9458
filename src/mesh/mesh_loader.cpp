// assimp -> TriangleMesh: one flat vertex array for all the file's meshes.
#include "sphere_tree_collision/mesh_loader.hpp"

#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>

namespace stc {
namespace {

const std::string kFileScheme = "file://";

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// What assimp may open besides the bytes it is given: nothing. An OBJ's
// mtllib or a DAE's external reference finds no file (assimp warns and goes
// on), so no path outside the checked one is ever read.
class NoFiles : public Assimp::IOSystem {
 public:
  bool Exists(const char*) const override { return false; }
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream* Open(const char*, const char*) override { return nullptr; }
  void Close(Assimp::IOStream* stream) override { delete stream; }
};

// The same words for a file that is missing and one outside the roots, with
// the resource as given (never its canonical path, which would show where a
// symlink leads): the answer tells nothing of what lies outside.
[[noreturn]] void refuseOutside(const std::string& resource, const std::vector<std::string>& roots) {
  std::string where = roots.empty() ? "no ~mesh_roots are set: only package:// is read" : "~mesh_roots:";
  for (std::size_t i = 0; i < roots.size(); ++i) where += (i == 0 ? " " : ", ") + roots[i];
  throw InputError("mesh_resource", resource + ": no such file under the folders meshes may be read from (" +
                                        where + ")");
}

void validateScale(const Vec3& scale) {
  if (!scale.allFinite() || !(scale.minCoeff() > 0.0)) {
    throw InputError("scale", "every component must be finite and > 0, got (" + number(scale.x()) + ", " +
                                  number(scale.y()) + ", " + number(scale.z()) + ")");
  }
}

// "<source>: <count> <what> above <limit name> <limit>": one wording for every mesh limit.
[[noreturn]] void refuseAbove(const std::string& source, std::int64_t count, const char* what,
                              const char* limit_name, std::int64_t limit) {
  throw InputError("mesh_resource", source + ": " + std::to_string(count) + " " + what + " above " + limit_name +
                                        " " + std::to_string(limit));
}

// Two things in a DAE's bytes that assimp (5.2) cannot be given, found in
// the plain bytes (an element's name cannot be escaped in XML; a `<p>` whose
// text is not plain is refused whole, entities and CDATA included):
// - <instance_node>: assimp copies the node for every instance, nested ones
//   too, before anything can count the copies: 5 KB nesting ten instances
//   nine deep asked for 10^9 nodes (gigabytes), and one naming its own
//   ancestor recurses without end.
// - a <p> (a primitive's indices) holding anything but integers: assimp's
//   reader does not move past a character it cannot read and appends an index
//   for ever (fuzz_mesh found it: the node would hang, its memory growing).
// An OBJ's `mtllib` lines made comments: assimp is given no file system, so a
// material library is never read, and its OBJ reader, after an unread
// `mtllib`, writes through a null material at a texture statement (`map_Kd`,
// `bump`): fuzz_mesh found it, a crash of the node. Only geometry is used.
std::string withoutMaterialLibraries(std::string_view obj) {
  std::string text(obj);
  std::size_t line = 0;
  while (line < text.size()) {
    std::size_t first = text.find_first_not_of(" \t", line);
    if (first != std::string::npos && text.compare(first, 6, "mtllib") == 0) text[first] = '#';
    const std::size_t end = text.find('\n', line);
    if (end == std::string::npos) break;
    line = end + 1;
  }
  return text;
}

void refuseWhatAssimpMishandles(std::string_view dae, const std::string& source) {
  if (dae.find("instance_node") != std::string_view::npos) {
    throw InputError("mesh_resource", source + ": <instance_node> is not read (assimp copies instanced nodes "
                                               "before they can be counted); flatten the file's nodes");
  }
  // Each byte is looked at a bounded number of times (the next search starts
  // past the text just checked): no quadratic scan of a file of "<p <p <p".
  std::size_t at = dae.find("<p");
  while (at != std::string_view::npos) {
    const char next = at + 2 < dae.size() ? dae[at + 2] : '\0';
    if (next != '>' && next != '/' && !std::isspace(static_cast<unsigned char>(next))) {  // <param ...
      at = dae.find("<p", at + 2);
      continue;
    }
    const std::size_t open_end = dae.find('>', at);
    if (open_end == std::string_view::npos) return;  // cut off: assimp refuses it
    const std::size_t text_end = std::min(dae.find('<', open_end), dae.size());
    const std::string_view text = dae.substr(open_end + 1, text_end - open_end - 1);
    const bool empty_element = dae[open_end - 1] == '/';  // <p/>
    const bool plain = text.find_first_not_of("0123456789+- \t\r\n") == std::string_view::npos &&
                       (text_end == dae.size() || dae.substr(text_end, 2) == "</");
    if (!empty_element && !plain) {
      throw InputError("mesh_resource", source + ": a <p> holds more than integers (at byte " +
                                            std::to_string(open_end + 1) + ")");
    }
    at = dae.find("<p", text_end);
  }
}

bool isUnder(const std::filesystem::path& path, const std::filesystem::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a root's trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

// The scene's triangles: every mesh at every node that draws it, with the
// node transforms applied (as aiProcess_PreTransformVertices would), counted
// first: a DAE whose nodes draw one mesh many times is refused by the limits
// before any copy is made.
class SceneFlattener {
 public:
  SceneFlattener(const aiScene& scene, const std::string& source, const Vec3& scale, bool to_z_up,
                 const MeshLimits& limits)
      : scene_(scene), source_(source), scale_(scale), to_z_up_(to_z_up), limits_(limits) {}

  TriangleMesh run() {
    if (scene_.mRootNode == nullptr) return {};
    std::int64_t vertices = 0, triangles = 0;
    count(*scene_.mRootNode, 0, vertices, triangles);
    if (vertices > limits_.max_mesh_vertices) {
      refuseAbove(source_, vertices, "vertices", "max_mesh_vertices", limits_.max_mesh_vertices);
    }
    if (triangles > limits_.max_mesh_triangles) {
      refuseAbove(source_, triangles, "triangles", "max_mesh_triangles", limits_.max_mesh_triangles);
    }
    mesh_.vertices.reserve(static_cast<std::size_t>(vertices));
    mesh_.triangles.reserve(static_cast<std::size_t>(triangles));
    copy(*scene_.mRootNode, aiMatrix4x4());
    return std::move(mesh_);
  }

 private:
  static std::int64_t triangleCount(const aiMesh& mesh) {
    std::int64_t n = 0;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) n += mesh.mFaces[f].mNumIndices == 3 ? 1 : 0;
    return n;
  }

  // Saturates at 2^62: the limits are below 2^31, so the counts stay exact up to them.
  static void addSaturated(std::int64_t& total, std::int64_t n) {
    total = std::min<std::int64_t>(total + std::min<std::int64_t>(n, kSaturated), kSaturated);
  }

  void count(const aiNode& node, int depth, std::int64_t& vertices, std::int64_t& triangles) const {
    if (depth > kMaxDepth) {
      throw InputError("mesh_resource", source_ + ": nodes nested deeper than " + std::to_string(kMaxDepth));
    }
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      if (node.mMeshes[i] >= scene_.mNumMeshes) {
        throw InputError("mesh_resource", source_ + ": a node names a mesh the file does not hold");
      }
      const aiMesh& mesh = *scene_.mMeshes[node.mMeshes[i]];
      addSaturated(vertices, mesh.mNumVertices);
      addSaturated(triangles, triangleCount(mesh));
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) count(*node.mChildren[c], depth + 1, vertices, triangles);
  }

  void copy(const aiNode& node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) add(*scene_.mMeshes[node.mMeshes[i]], transform);
    for (unsigned c = 0; c < node.mNumChildren; ++c) copy(*node.mChildren[c], transform);
  }

  void add(const aiMesh& in, const aiMatrix4x4& transform) {
    // Below max_mesh_vertices (counted, < 2^31): every index fits.
    const auto base = static_cast<std::int32_t>(mesh_.vertices.size());
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiVector3D p = transform * in.mVertices[v];
      // assimp's y up to ROS's z up: +90 degrees about x.
      const Vec3 vertex = to_z_up_ ? Vec3(p.x, -p.z, p.y) : Vec3(p.x, p.y, p.z);
      mesh_.vertices.push_back(vertex.cwiseProduct(scale_));
    }
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      const aiFace& face = in.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines enclose nothing
      std::array<std::int32_t, 3> t;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= in.mNumVertices) {
          throw InputError("mesh_resource", source_ + ": a face names a vertex its mesh does not hold");
        }
        t[k] = base + static_cast<std::int32_t>(face.mIndices[k]);
      }
      mesh_.triangles.push_back(t);
    }
  }

  static constexpr int kMaxDepth = 256;
  static constexpr std::int64_t kSaturated = std::int64_t{1} << 62;
  const aiScene& scene_;
  const std::string& source_;
  const Vec3 scale_;
  const bool to_z_up_;
  const MeshLimits& limits_;
  TriangleMesh mesh_;
};

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

std::string meshFormatOf(const std::string& path, const std::string& source) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".stl" || ext == ".obj" || ext == ".dae") return ext.substr(1);
  throw InputError("mesh_resource", source + ": only .stl, .obj and .dae files are read");
}

std::vector<std::string> canonicalMeshRoots(const std::vector<std::string>& roots, const std::string& field) {
  std::vector<std::string> canonical;
  for (std::size_t i = 0; i < roots.size(); ++i) {
    const std::string name = field + "[" + std::to_string(i) + "]";
    const std::filesystem::path root(roots[i]);
    if (!root.is_absolute()) throw InputError(name, "'" + roots[i] + "' is not an absolute path");
    std::error_code error;
    const std::filesystem::path real = std::filesystem::canonical(root, error);
    if (error || !std::filesystem::is_directory(real, error)) {
      throw InputError(name, "'" + roots[i] + "' is not a folder");
    }
    canonical.push_back(real.string());
  }
  return canonical;
}

std::string meshPathWithinRoots(const std::string& resource, const std::vector<std::string>& roots) {
  const std::string path = meshResourcePath(resource);
  // `..` and every symlink resolved before the test (canonical: the file must
  // exist), so neither leads out; the canonical path is what is then opened.
  std::error_code error;
  const std::filesystem::path real = std::filesystem::canonical(path, error);
  if (!error) {
    for (const std::string& root : roots) {
      if (isUnder(real, root)) return real.string();
    }
  }
  refuseOutside(resource, roots);
}

TriangleMesh parseTriangleMesh(const void* bytes, std::size_t size, const std::string& format,
                               const std::string& source, const Vec3& scale, ColladaUpAxis up_axis,
                               const MeshLimits& limits) {
  validateScale(scale);
  if (format != "stl" && format != "obj" && format != "dae") meshFormatOf(format, source);  // throws
  if (size > static_cast<std::uint64_t>(limits.max_mesh_bytes)) {
    refuseAbove(source, static_cast<std::int64_t>(size), "bytes", "max_mesh_bytes", limits.max_mesh_bytes);
  }
  if (format == "dae") refuseWhatAssimpMishandles(std::string_view(static_cast<const char*>(bytes), size), source);
  Assimp::Importer importer;
  importer.SetIOHandler(new NoFiles);  // owned by the importer
  // assimp turns a DAE whose up axis is not Y_UP so that it is (its root
  // node's transform), unless told to ignore the up axis; the unit is
  // applied either way.
  const bool to_z_up = up_axis == ColladaUpAxis::ToZUp && format == "dae";
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, !to_z_up);
  // No welding or normal fixing: the voxeliser copes with duplicated vertices
  // and reports them. Node transforms are applied by SceneFlattener.
  std::string obj;
  if (format == "obj") {
    obj = withoutMaterialLibraries(std::string_view(static_cast<const char*>(bytes), size));
    bytes = obj.data();
  }
  const aiScene* scene = importer.ReadFileFromMemory(bytes, size, aiProcess_Triangulate, format.c_str());
  if (scene == nullptr) {
    throw InputError("mesh_resource", source + ": cannot be read: " + importer.GetErrorString());
  }
  TriangleMesh mesh = SceneFlattener(*scene, source, scale, to_z_up, limits).run();
  if (mesh.triangles.empty()) throw InputError("mesh_resource", source + ": holds no triangle");
  return mesh;
}

TriangleMesh loadTriangleMesh(const std::string& resource, const Vec3& scale, ColladaUpAxis up_axis,
                              const MeshLimits& limits) {
  validateScale(scale);
  const std::string path = meshResourcePath(resource);
  const std::string format = meshFormatOf(path, resource);
  // Devices, pipes and directories are refused before they are opened (a
  // read of /dev/stdin would block), a file too large before it is read.
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError("mesh_resource", resource + ": not a regular file");
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) throw InputError("mesh_resource", resource + ": cannot be read");
  if (size > static_cast<std::uintmax_t>(limits.max_mesh_bytes)) {
    refuseAbove(resource, static_cast<std::int64_t>(std::min<std::uintmax_t>(size, INT64_MAX)), "bytes",
                "max_mesh_bytes", limits.max_mesh_bytes);
  }
  std::ifstream in(path, std::ios::binary);
  // One byte more than its size: a file that grew since is not read on.
  std::vector<char> bytes(static_cast<std::size_t>(size) + 1);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (in.bad()) throw InputError("mesh_resource", resource + ": cannot be read");
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  if (bytes.size() > size) throw InputError("mesh_resource", resource + ": changed while it was read");
  return parseTriangleMesh(bytes.data(), bytes.size(), format, resource, scale, up_axis, limits);
}

}  // namespace stc
