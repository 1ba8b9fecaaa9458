#include "sphere_tree_collision/ros/mesh_resource.hpp"

#include "sphere_tree_collision/types.hpp"

#include <ros/package.h>

namespace stc_ros {

std::string resolveMeshResource(const std::string& resource) {
  const std::string scheme = "package://";
  if (resource.compare(0, scheme.size(), scheme) != 0) return resource;
  const std::size_t slash = resource.find('/', scheme.size());
  if (slash == std::string::npos || slash + 1 == resource.size()) {
    throw stc::InputError("mesh_resource", resource + ": expected package://<package>/<path>");
  }
  const std::string package = resource.substr(scheme.size(), slash - scheme.size());
  const std::string root = ros::package::getPath(package);
  if (root.empty()) throw stc::InputError("mesh_resource", resource + ": package '" + package + "' not found");
  return root + resource.substr(slash);
}

}  // namespace stc_ros
