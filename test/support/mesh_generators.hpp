// Triangle meshes made in code for the mesh tests and the mesh accuracy bench
// (no downloads): a cube, an icosphere, a robot-link-like capsule and flange
// with a small defect, and a bumpy star-shaped "scan".
#pragma once

#include "sphere_tree_collision/mesh_voxeliser.hpp"

#include <cstdint>

namespace stc::truth {

// Axis-aligned cube [0, side]^3, 12 triangles, outward.
TriangleMesh cubeMesh(double side);
// Axis-aligned box [lo, hi], 12 triangles, outward.
TriangleMesh boxMesh(const Vec3& lo, const Vec3& hi);
// Icosahedron subdivided `subdivisions` times, vertices on the sphere of
// `radius` about the origin; 20 * 4^subdivisions triangles, outward.
TriangleMesh icosphere(double radius, int subdivisions);
// Every triangle with its own three vertices, as an STL file stores them.
TriangleMesh unwelded(const TriangleMesh& mesh);
// The triangles of both meshes in one (overlapping closed parts stay as they are).
TriangleMesh merged(const TriangleMesh& a, const TriangleMesh& b);

// A robot link: a capsule (radius 0.05 m, 0.3 m between the cap centres,
// along x) through a box flange (0.04 x 0.16 x 0.16 m) at one end, unwelded
// (duplicated vertices) and with one small capsule triangle missing (a hole
// narrower than a voxel of 1/32 of the length).
TriangleMesh robotLinkMesh();
// A bunny-sized (~0.15 m) star-shaped scan: an icosphere whose radius is
// displaced by low-frequency lobes and seeded bumps.
TriangleMesh bumpyScanMesh(std::uint32_t seed = 7);

// Volume enclosed by a closed, outward mesh (divergence theorem).
double enclosedVolume(const TriangleMesh& mesh);
// Generalised winding number of p (sum of the triangles' signed solid angles
// / 4 pi): 1 inside a closed outward mesh, 0 outside, about right near a
// small hole; > 0.5 means inside.
double windingNumber(const TriangleMesh& mesh, const Vec3& p);

}  // namespace stc::truth
