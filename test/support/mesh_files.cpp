#include "mesh_files.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace stc::truth {
namespace {

std::ofstream open(const std::string& path, bool binary = false) {
  std::ofstream out(path, binary ? std::ios::binary : std::ios::out);
  if (!out) throw std::runtime_error("cannot write " + path);
  out.precision(17);
  return out;
}

Vec3 normalOf(const TriangleMesh& m, const std::array<std::int32_t, 3>& t) {
  const Vec3 n = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
  return n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3::Zero();
}

}  // namespace

void writeStlAscii(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out = open(path);
  out << "solid generated\n";
  for (const auto& t : mesh.triangles) {
    const Vec3 n = normalOf(mesh, t);
    out << " facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\n  outer loop\n";
    for (std::int32_t v : t) {
      const Vec3& p = mesh.vertices[static_cast<std::size_t>(v)];
      out << "   vertex " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    }
    out << "  endloop\n endfacet\n";
  }
  out << "endsolid generated\n";
}

void writeStlBinary(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out = open(path, true);
  char header[80] = {};
  std::strncpy(header, "binary STL written by the sphere_tree_collision tests", sizeof header - 1);
  out.write(header, sizeof header);
  const auto count = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);  // little-endian hosts only (x86, arm)
  for (const auto& t : mesh.triangles) {
    float record[12];
    const Vec3 n = normalOf(mesh, t);
    for (int c = 0; c < 3; ++c) record[c] = static_cast<float>(n[c]);
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) record[3 + 3 * v + c] = static_cast<float>(mesh.vertices[t[v]][c]);
    out.write(reinterpret_cast<const char*>(record), sizeof record);
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
}

void writeObj(const TriangleMesh& mesh, const std::string& path) {
  std::ofstream out = open(path);
  for (const Vec3& p : mesh.vertices) out << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : mesh.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
}

void writeDae(const TriangleMesh& mesh, const std::string& path, const std::string& up_axis,
              double metres_per_unit) {
  std::ofstream out = open(path);
  out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
         "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
         " <asset><unit name=\"unit\" meter=\"" << metres_per_unit << "\"/><up_axis>" << up_axis
      << "</up_axis></asset>\n"
         " <library_geometries><geometry id=\"shape\"><mesh>\n"
         "  <source id=\"shape-positions\">\n"
         "   <float_array id=\"shape-positions-array\" count=\"" << 3 * mesh.vertices.size() << "\">";
  for (const Vec3& p : mesh.vertices) out << p.x() << ' ' << p.y() << ' ' << p.z() << ' ';
  out << "</float_array>\n"
         "   <technique_common><accessor source=\"#shape-positions-array\" count=\"" << mesh.vertices.size()
      << "\" stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
         "<param name=\"Z\" type=\"float\"/></accessor></technique_common>\n"
         "  </source>\n"
         "  <vertices id=\"shape-vertices\"><input semantic=\"POSITION\" source=\"#shape-positions\"/></vertices>\n"
         "  <triangles count=\"" << mesh.triangles.size() << "\"><input semantic=\"VERTEX\" source=\"#shape-vertices\" offset=\"0\"/><p>";
  for (const auto& t : mesh.triangles) out << t[0] << ' ' << t[1] << ' ' << t[2] << ' ';
  out << "</p></triangles>\n"
         " </mesh></geometry></library_geometries>\n"
         " <library_visual_scenes><visual_scene id=\"scene\"><node id=\"node\">"
         "<instance_geometry url=\"#shape\"/></node></visual_scene></library_visual_scenes>\n"
         " <scene><instance_visual_scene url=\"#scene\"/></scene>\n"
         "</COLLADA>\n";
}

}  // namespace stc::truth
