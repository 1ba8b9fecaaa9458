// Writers of the mesh file formats the loader reads, so tests make their own
// files: STL (ASCII and binary), OBJ and COLLADA (DAE, Z up, metres).
#pragma once

#include "sphere_tree_collision/mesh_voxeliser.hpp"

#include <string>

namespace stc::truth {

void writeStlAscii(const TriangleMesh& mesh, const std::string& path);
void writeStlBinary(const TriangleMesh& mesh, const std::string& path);
void writeObj(const TriangleMesh& mesh, const std::string& path);
void writeDae(const TriangleMesh& mesh, const std::string& path);

}  // namespace stc::truth
