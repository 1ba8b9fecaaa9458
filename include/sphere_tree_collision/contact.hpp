// Contact: what the response phase gets from one intersecting sphere pair
// (paper 3.5, Fig. 4): normal along the line of centres, point dividing it
// in proportion to the radii.
#pragma once

#include "sphere_tree_collision/types.hpp"

namespace stc {

// Contact::node_a/node_b of the swept test's hit (Physics::appendSweepHit):
// an impact at one instant, not a load the pair carries, so the solver's warm
// start neither gives it an impulse nor takes one from it.
constexpr std::int32_t kSweepHitNode = -1;
// The node of a contact's other side when it was measured against that
// body's solid (its interior field), not against a sphere of its tree: one
// body pressed more than a voxel into the other.
constexpr std::int32_t kInteriorNode = -2;

struct Contact {
  EntityId a = kInvalidEntity;
  EntityId b = kInvalidEntity;
  std::uint32_t index_a = 0;  // dense body index in the World this tick
  std::uint32_t index_b = 0;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit, from a towards b
  double depth = 0.0;           // sphere overlap along the normal (>= 0)
  double gap_bound = 0.0;       // h_a + h_b of the pair's frontier this tick: the true gap is at most this
  // h_a + h_b of the frontier the contact's spheres were found at: gap_bound,
  // but for a contact an unresolved pair kept from a deeper frontier of an
  // earlier tick (Physics' steady frontier), that frontier's. The scale of the
  // solver's slop and of its warm-start match.
  double sphere_bound = 0.0;
  int level = 0;                // deepest tree level the pair reached
  bool resolved = false;        // true: found at the leaves; false: accepted unresolved
  double priority = 0.0;        // perceptual priority f(e, g) (0 without gaze)
  // Signed gap between the two shapes' surfaces along the normal (< 0:
  // penetration), each surface taken where its sphere's voxel box ends
  // (ShapeBounds::support in response.hpp): what the solver acts on. At
  // least 0 for an accepted unresolved pair, whose overlap is not proven.
  double separation = 0.0;
  std::int32_t node_a = 0;      // sphere pair the contact was built from (tree node indices;
  std::int32_t node_b = 0;      // kSweepHitNode: the swept test's hit, of no sphere pair;
                                // kInteriorNode: the side measured by its solid)
  // Filled in by the solver: impulses applied at the point this tick (N s, world).
  double normal_impulse = 0.0;
  Vec3 friction_impulse = Vec3::Zero();
};

}  // namespace stc
