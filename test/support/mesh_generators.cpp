#include "mesh_generators.hpp"

#include "pose_sampling.hpp"

#include <cmath>
#include <map>
#include <utility>

namespace stc::truth {

TriangleMesh boxMesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int c = 0; c < 8; ++c) m.vertices.emplace_back(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z());
  // Two triangles per face, counter-clockwise seen from outside.
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

TriangleMesh cubeMesh(double side) { return boxMesh(Vec3::Zero(), Vec3::Constant(side)); }

TriangleMesh icosphere(double radius, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh m;
  m.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (Vec3& v : m.vertices) v.normalize();
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> midpoint;
    const auto mid = [&](std::int32_t a, std::int32_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      const auto id = static_cast<std::int32_t>(m.vertices.size() - 1);
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<std::int32_t, 3>> next;
    for (const auto& tri : m.triangles) {
      const std::int32_t ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles = std::move(next);
  }
  for (Vec3& v : m.vertices) v *= radius;
  return m;
}

TriangleMesh unwelded(const TriangleMesh& mesh) {
  TriangleMesh out;
  for (const auto& t : mesh.triangles) {
    const auto base = static_cast<std::int32_t>(out.vertices.size());
    for (std::int32_t v : t) out.vertices.push_back(mesh.vertices[static_cast<std::size_t>(v)]);
    out.triangles.push_back({base, base + 1, base + 2});
  }
  return out;
}

TriangleMesh merged(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out = a;
  const auto base = static_cast<std::int32_t>(a.vertices.size());
  out.vertices.insert(out.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& t : b.triangles) out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return out;
}

TriangleMesh robotLinkMesh() {
  // Capsule: a sphere of radius r cut at its equator, the halves pulled apart by `length`.
  const double r = 0.05, length = 0.3;
  TriangleMesh capsule = icosphere(r, 3);
  // Vertices with x > 0 move by +length/2, the others by -length/2: the
  // triangles straddling the cut stretch into the shaft; the surface stays closed.
  for (Vec3& v : capsule.vertices) v.x() += v.x() > 0.0 ? length / 2 : -length / 2;
  // One triangle of the free cap missing: a hole narrower than a voxel.
  std::size_t tip = 0;
  for (std::size_t t = 0; t < capsule.triangles.size(); ++t) {
    const auto& tri = capsule.triangles[t];
    const double x = (capsule.vertices[tri[0]] + capsule.vertices[tri[1]] + capsule.vertices[tri[2]]).x();
    const auto& best = capsule.triangles[tip];
    if (x < (capsule.vertices[best[0]] + capsule.vertices[best[1]] + capsule.vertices[best[2]]).x()) tip = t;
  }
  capsule.triangles.erase(capsule.triangles.begin() + static_cast<std::ptrdiff_t>(tip));
  const TriangleMesh flange = boxMesh(Vec3(length / 2 - 0.02, -0.08, -0.08), Vec3(length / 2 + 0.02, 0.08, 0.08));
  return unwelded(merged(capsule, flange));
}

TriangleMesh bumpyScanMesh(std::uint32_t seed) {
  TriangleMesh m = icosphere(1.0, 4);
  Rng rng(seed);
  struct Bump {
    Vec3 dir;
    double height, width;
  };
  std::vector<Bump> bumps;
  for (int b = 0; b < 24; ++b) bumps.push_back({randomDirection(rng), randomUniform(rng, -0.06, 0.1), randomUniform(rng, 0.15, 0.4)});
  for (Vec3& v : m.vertices) {
    const Vec3 u = v.normalized();
    // Lobes like ears and a body, then bumps; the radius stays positive: star-shaped.
    double radius = 1.0 + 0.25 * std::max(0.0, u.z()) * std::max(0.0, u.z()) * std::max(0.0, u.y()) +
                    0.12 * std::sin(3.0 * u.x()) * std::cos(2.0 * u.y());
    for (const Bump& b : bumps) radius += b.height * std::exp(-(u - b.dir).squaredNorm() / (b.width * b.width));
    v = 0.075 * radius * u;  // ~0.15 m across
  }
  return m;
}

double enclosedVolume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
  return volume;
}

double windingNumber(const TriangleMesh& mesh, const Vec3& p) {
  double total = 0.0;
  for (const auto& t : mesh.triangles) {
    // Signed solid angle of the triangle seen from p (Van Oosterom and Strackee).
    const Vec3 a = mesh.vertices[t[0]] - p, b = mesh.vertices[t[1]] - p, c = mesh.vertices[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2.0 * std::atan2(numerator, denominator);
  }
  return total / (4.0 * M_PI);
}

}  // namespace stc::truth
