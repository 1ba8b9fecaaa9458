// Mesh resources named as rviz names them: package://pkg/path resolved
// through roslib to a file path in that package; file:// and plain paths
// read only from the folders of ~mesh_roots.
#pragma once

#include <string>
#include <vector>

namespace stc_ros {

// The path of the file a resource names. package://pkg/path always resolves,
// within the package's folder (a `..` leading out is refused); a file:// URI
// or a path only to an existing file under one of `roots` (canonical:
// stc::canonicalMeshRoots; none: only package:// is read), given as its
// canonical path. Throws stc::InputError("mesh_resource") when the package is
// not found, the resource has no path after the package name, or the path
// leads out of the package, or is not a file under the roots (the same words
// for a missing file and one outside them).
std::string resolveMeshResource(const std::string& resource, const std::vector<std::string>& roots);

}  // namespace stc_ros
