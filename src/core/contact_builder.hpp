// Contacts from the intersecting sphere pairs of a PairTest (paper 3.5, Fig. 4).
#pragma once

#include "interior_field.hpp"
#include "pair_test.hpp"
#include "shape_bounds.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/types.hpp"

#include <cstdint>
#include <limits>
#include <vector>

namespace stc {

struct ContactBuildOptions {
  int max_contacts_per_pair = 4;
  bool accept_unresolved = true;  // policy accept: unresolved pairs give contacts too
  bool face_normals = true;       // see ContactBuilder; false: the paper's line of centres only
};

// One intersecting sphere pair a contact may be built from (world frame).
struct ContactCandidate {
  Vec3 ca, cb;                 // the two spheres' centres
  Vec3 point, normal;          // normal: unit, a -> b
  double overlap = 0.0;        // r_a + r_b - |c_b - c_a|
  double separation = 0.0;     // gap between the surfaces along normal (once refined)
  std::int32_t node_a = 0, node_b = 0;
  int cluster = 0;             // position of its representative among the picked ones
  double nearest = 0.0;        // squared distance to that representative's point
  bool refined = false;        // separation and face normal evaluated (deep enough)
};

// One body's surface as the contact steps see it: its shape's node bounds
// (nullptr: the surface is the sphere), for a static body the faces of its
// node boxes other static bodies cover (StaticCover::of; nullptr: none), and
// its solid (nullptr: no contacts from inside it).
struct BodySurface {
  const ShapeBounds* bounds = nullptr;
  const std::uint8_t* covered_faces = nullptr;
  const InteriorField* interior = nullptr;
};

// The two bodies of a pair as the contact steps see them: trees, surfaces and poses.
class PairGeometry {
 public:
  PairGeometry(const PairTest& test, const BodySurface& a, const BodySurface& b);
  PairGeometry(const PairTest& test, const ShapeBounds* bounds_a, const ShapeBounds* bounds_b)
      : PairGeometry(test, BodySurface{bounds_a, nullptr}, BodySurface{bounds_b, nullptr}) {}

  // Paper Fig. 4: normal along the line of centres a -> b (coincident: the
  // body centres, then +Z), point dividing the centres in proportion to the radii.
  ContactCandidate candidate(std::int32_t node_a, std::int32_t node_b) const;
  // A unit direction (world, a -> b) as the gaps along it read it: in A's
  // frame, and reversed in B's. Made once, it serves every candidate.
  struct Axis {
    Vec3 world, in_a, reversed_in_b;
  };
  Axis axis(const Vec3& n) const { return Axis{n, rot_a_.transpose() * n, rot_b_.transpose() * (-n)}; }
  // Gap between the two nodes' surfaces along unit n (world, a -> b).
  double gapAlong(const ContactCandidate& c, const Axis& n) const;
  double gapAlong(const ContactCandidate& c, const Vec3& n) const { return gapAlong(c, axis(n)); }
  // Separation along the candidate's normal; with face_normals and bounds, a
  // face axis of either voxel box that separates the nodes more becomes the
  // normal, and the point moves to the middle of the faces' overlap. A face
  // another static body covers is not a surface: its axis is skipped.
  void refine(ContactCandidate& c, bool face_normals) const;
  // Bodies inside each other: a candidate for every leaf of either body whose
  // centre lies in the other's solid (InteriorField), normal the other's way
  // out (through no covered face), separation minus how deep the leaf's voxel
  // box reaches in. The other side's node is kInteriorNode. `stack`: scratch.
  void interiorCandidates(const InteriorField& field_a, const InteriorField& field_b,
                          std::vector<std::int32_t>& stack, std::vector<ContactCandidate>& out) const;

 private:
  // Surface of a node towards a direction in its own body frame.
  double localSupportA(std::int32_t node, const Vec3& dir_a) const;
  double localSupportB(std::int32_t node, const Vec3& dir_b) const;
  Vec3 faceContactPoint(const ContactCandidate& c) const;
  // A face normal's tangents and its directions in both body frames. A
  // pair's face candidates mostly share one normal: the last one is kept.
  struct FaceFrame {
    bool valid = false;
    Vec3 normal;
    Vec3 tangent[2];
    Axis across;
    Vec3 tangent_in_a[2], tangent_in_b[2];
  };
  const FaceFrame& faceFrame(const Vec3& normal) const;
  // Whether n (a -> b) points through a covered face of a's node (mask_a),
  // or -n through one of b's node; and n with those parts removed.
  bool intoCover(std::uint8_t mask_a, std::uint8_t mask_b, const Vec3& n) const;
  Vec3 awayFromCover(std::uint8_t mask_a, std::uint8_t mask_b, const Vec3& n) const;
  // interiorCandidates one way: the leaves of `from` (a's tree when from_a) in `into`'s solid.
  void leavesInside(bool from_a, const InteriorField& into, std::vector<std::int32_t>& stack,
                    std::vector<ContactCandidate>& out) const;

  const SphereTree& tree_a_;
  const SphereTree& tree_b_;
  const ShapeBounds* bounds_a_;
  const ShapeBounds* bounds_b_;
  const std::uint8_t* covered_a_;
  const std::uint8_t* covered_b_;
  Mat3 rot_a_, rot_b_;
  Mat3 b_in_a_;  // B's axes in A's frame (columns)
  Mat3 a_in_b_;  // A's axes in B's frame: its transpose
  Mat3 abs_b_in_a_, abs_a_in_b_;  // their absolute values: a box's half extents along the other's axes
  Vec3 pos_a_, pos_b_;
  mutable FaceFrame face_frame_;  // faceFrame's last: a cache, not state
};

// The steps of ContactBuilder::append, each usable alone.

// 1. Candidates: the test's lastPairs(), or the roots when no sphere was tested.
void gatherCandidates(const PairTest& test, const PairGeometry& geometry, std::vector<ContactCandidate>& out);
// Largest overlap of the candidates (-infinity when there are none).
double deepestOverlap(const std::vector<ContactCandidate>& candidates);
// 2. Refines (PairGeometry::refine) the candidates with at least half the
// deepest overlap (only the deepest when nothing overlaps); only those can
// represent the pair.
void refineDeepCandidates(std::vector<ContactCandidate>& candidates, double deepest, const PairGeometry& geometry,
                          bool face_normals);
// 2b. Drops the candidates refineDeepCandidates left unrefined: they can
// neither represent the pair nor give a cluster its normal, and on a face of
// leaf spheres, where they are four in five (the neighbours across, their
// lines of centres 45 degrees off the face), none measures a separation
// either. The steps after it walked past them, pair after pair.
void dropShallowCandidates(std::vector<ContactCandidate>& candidates);
// Most representatives a pair can have (ContactBuildOptions::max_contacts_per_pair).
constexpr int kMaxRepresentatives = 16;

// 3. Up to `limit` (clamped to 1..kMaxRepresentatives) representatives spread out among the
// refined candidates: first the deepest (within 1e-3 times the smallest reach)
// farthest from the centroid, then the farthest from it, then the largest
// triangle, then the farthest from all picked; points closer than 1e-6 times the
// smallest reach count as one. Fills `reps` with candidate indices. Each
// candidate keeps its distance to the nearest picked one as they are picked,
// so it leaves every candidate in its cluster, as assignClusters does.
void pickRepresentatives(std::vector<ContactCandidate>& candidates, double deepest, int limit,
                         std::vector<int>& reps);
// Where the candidates lie, as pickRepresentatives measures from it: the mean
// of their points and their smallest reach (r_a + r_b, the length unit).
struct CandidateSpread {
  Vec3 centroid = Vec3::Zero();
  double scale = std::numeric_limits<double>::infinity();
};
CandidateSpread spreadOf(const std::vector<ContactCandidate>& candidates);
// ... measuring from `spread` (spreadOf the set before dropShallowCandidates).
void pickRepresentatives(std::vector<ContactCandidate>& candidates, double deepest, int limit,
                         const CandidateSpread& spread, std::vector<int>& reps);
// 4. Every candidate joins its nearest representative (cluster = position in
// reps; a tie goes to the earlier one).
void assignClusters(std::vector<ContactCandidate>& candidates, const std::vector<int>& reps);
// 5. Each cluster's normal (normals[r] for reps[r]): the mean over its
// refined members with sphere overlap within 10% of its deepest (the pairs
// straight across the contact); the representative's when that mean is zero
// or not finite.
void clusterNormals(const std::vector<ContactCandidate>& candidates, const std::vector<int>& reps,
                    std::vector<Vec3>& normals);
// ... and its separation along its normal: the smallest gap of the members
// whose own normal lies within about 18 degrees of it; the representative's
// when none does.
void clusterSeparations(const std::vector<ContactCandidate>& candidates, const std::vector<int>& reps,
                        const std::vector<Vec3>& normals, const PairGeometry& geometry,
                        std::vector<double>& separations);

// 6. Bodies inside each other. A pair whose contacts measure a penetration of
// more than kInteriorDepth of the smaller voxel may be deeper than its shells
// can measure (a cube pressed through the shell of the one below). Its
// contacts are then the interior candidates' (PairGeometry::interiorCandidates),
// picked and clustered as above, each cluster's separation its deepest aligned
// member's; false (and `candidates` untouched in meaning) when there are none.
constexpr double kInteriorDepth = 0.5;
bool interiorContacts(const PairGeometry& geometry, const InteriorField& field_a, const InteriorField& field_b,
                      int limit, std::vector<std::int32_t>& stack, std::vector<ContactCandidate>& candidates,
                      std::vector<int>& reps, std::vector<Vec3>& normals, std::vector<double>& separations);

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
// (ShapeBounds::support; the sphere itself without bounds), and at least 0
// for an Unresolved test: its overlap is the frontier's, not proven of the
// surfaces, so its contacts stop approach and push nothing apart. Coincident
// centres: the direction between the body centres, then +Z; never NaN.
// A cache line of its own: the parallel contact building gives each thread
// a builder, and its scratch vectors' ends move with every candidate.
class alignas(64) ContactBuilder {
 public:
  // Appends the contacts of one test (none when Separate, or Unresolved and not accepted).
  // bounds_a/bounds_b: of the test's trees, or nullptr (surface at the spheres).
  // The steps, in order: gatherCandidates, refineDeepCandidates, spreadOf,
  // dropShallowCandidates, pickRepresentatives (which assigns the clusters),
  // then one contact per cluster (clusterNormals, clusterSeparations).
  void append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b, double priority,
              const BodySurface& a, const BodySurface& b, const ContactBuildOptions& options,
              std::vector<Contact>& out);
  void append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b, double priority,
              const ShapeBounds* bounds_a, const ShapeBounds* bounds_b,
              const ContactBuildOptions& options, std::vector<Contact>& out) {
    append(test, index_a, index_b, priority, BodySurface{bounds_a, nullptr}, BodySurface{bounds_b, nullptr},
           options, out);
  }

 private:
  // Whether the smaller body's root centre lies in the other's solid (a Separate pair nested).
  static bool nested(const PairTest& test, const InteriorField& field_a, const InteriorField& field_b);
  // One contact per representative (reps_, normals_, separations_ of
  // candidates_); not proven (an unresolved pair's): separations at least 0.
  void emit(const PairTest& test, bool proven, std::uint32_t index_a, std::uint32_t index_b, double priority,
            std::vector<Contact>& out) const;

  std::vector<ContactCandidate> candidates_;  // scratch kept between pairs: no allocation per tick
  std::vector<int> reps_;
  std::vector<Vec3> normals_;
  std::vector<double> separations_;
  std::vector<std::int32_t> stack_;         // interiorContacts' tree walk
  std::vector<ContactCandidate> inside_;    // and its candidates
};

}  // namespace stc
