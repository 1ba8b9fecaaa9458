// Writers of the mesh file formats the loader reads, so tests make their own
// files: STL (ASCII and binary), OBJ and COLLADA (DAE; Z up and metres
// unless told otherwise).
#pragma once

#include "sphere_tree_collision/mesh_voxeliser.hpp"

#include <string>

namespace stc::truth {

void writeStlAscii(const TriangleMesh& mesh, const std::string& path);
void writeStlBinary(const TriangleMesh& mesh, const std::string& path);
void writeObj(const TriangleMesh& mesh, const std::string& path);
// up_axis: "X_UP", "Y_UP" or "Z_UP"; metres_per_unit: the <unit meter=...>.
void writeDae(const TriangleMesh& mesh, const std::string& path, const std::string& up_axis = "Z_UP",
              double metres_per_unit = 1.0);

}  // namespace stc::truth
