#include "sphere_tree_collision/ros/mesh_resource.hpp"

#include "sphere_tree_collision/mesh_loader.hpp"
#include "sphere_tree_collision/types.hpp"

#include <ros/package.h>

#include <filesystem>

namespace stc_ros {

std::string resolveMeshResource(const std::string& resource, const std::vector<std::string>& roots) {
  const std::string scheme = "package://";
  if (resource.compare(0, scheme.size(), scheme) != 0) return stc::meshPathWithinRoots(resource, roots);
  const std::size_t slash = resource.find('/', scheme.size());
  if (slash == std::string::npos || slash + 1 == resource.size()) {
    throw stc::InputError("mesh_resource", resource + ": expected package://<package>/<path>");
  }
  // Within the package's folder: a `..` that leads out is refused (a symlink
  // the package itself holds is followed, as rviz follows it).
  const std::filesystem::path inside = std::filesystem::path(resource.substr(slash + 1)).lexically_normal();
  if (inside.empty() || inside.is_absolute() || *inside.begin() == "..") {
    throw stc::InputError("mesh_resource", resource + ": leads out of its package");
  }
  const std::string package = resource.substr(scheme.size(), slash - scheme.size());
  const std::string root = ros::package::getPath(package);
  if (root.empty()) throw stc::InputError("mesh_resource", resource + ": package '" + package + "' not found");
  return (std::filesystem::path(root) / inside).string();
}

}  // namespace stc_ros
