// Contacts from the intersecting sphere pairs of a PairTest (paper 3.5, Fig. 4).
#pragma once

#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/pair_test.hpp"
#include "sphere_tree_collision/shape_bounds.hpp"

#include <cstdint>
#include <vector>

namespace stc {

struct ContactBuildOptions {
  int max_contacts_per_pair = 4;
  bool accept_unresolved = true;  // policy accept: unresolved pairs give contacts too
  bool face_normals = true;       // see ContactBuilder; false: the paper's line of centres only
};

// Builds the contacts of PairTests. Candidates are the test's lastPairs()
// (leaf pairs when Colliding, the frontier when accepted Unresolved, the roots
// when no sphere was tested). Per candidate (paper Fig. 4): normal along the
// line of centres a -> b, point dividing the centres in proportion to the
// radii. With face_normals and ShapeBounds, a face axis of either node's voxel
// box replaces the line of centres when it separates the two nodes more (the
// separating-axis rule): face-on, the line of centres of two voxel spheres
// tilts by up to 45 degrees, making floors bumpy and balls sit in dimples;
// the point is then the middle of the two boxes' overlap on the face plane,
// halfway between the surfaces. Only candidates with at least half the
// deepest sphere overlap are refined so and can represent the pair.
// Up to max_contacts_per_pair representatives are picked spread out among the
// deep candidates (deepest corner first, then farthest, then largest
// triangle); every candidate joins its nearest representative; the cluster's
// normal is the mean over its deepest members (sphere overlap within 10% of
// its deepest: the pairs straight across the contact). separation is
// measured along that normal between the nodes' surfaces
// (ShapeBounds::support; the sphere itself without bounds). Coincident
// centres: the direction between the body centres, then +Z; never NaN.
class ContactBuilder {
 public:
  // Appends the contacts of one test (none when Separate, or Unresolved and not accepted).
  // bounds_a/bounds_b: of the test's trees, or nullptr (surface at the spheres).
  void append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b, double priority,
              const ShapeBounds* bounds_a, const ShapeBounds* bounds_b,
              const ContactBuildOptions& options, std::vector<Contact>& out);

 private:
  struct Candidate {
    Vec3 ca, cb, point, normal;
    double overlap = 0.0;                     // r_a + r_b - |c_b - c_a|
    double separation = 0.0;                  // gap between the surfaces along normal
    std::int32_t node_a = 0, node_b = 0;
    int cluster = 0;
    bool refined = false;                     // separation and face normal evaluated (deep enough)
  };
  std::vector<Candidate> candidates_;
  std::vector<int> reps_;
};

}  // namespace stc
