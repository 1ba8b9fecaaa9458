// Mesh resources named as rviz names them: package://pkg/path resolved
// through roslib to a file path; file:// and plain paths are left to the core.
#pragma once

#include <string>

namespace stc_ros {

// Throws stc::InputError("mesh_resource") when the package is not found or
// the resource has no path after the package name.
std::string resolveMeshResource(const std::string& resource);

}  // namespace stc_ros
