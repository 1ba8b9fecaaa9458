// Contacts from the intersecting sphere pairs of a PairTest (paper 3.5, Fig. 4).
#include "contact_builder.hpp"

#include "contact_solver.hpp"  // tangentBasis
#include "static_cover.hpp"    // faceBit

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {
namespace {

// Candidates at least this fraction of the deepest overlap can become
// representatives: on a face of leaf spheres the pairs straight across
// overlap about twice as much as the tilted neighbour pairs, which would
// otherwise put contact points half a voxel outside the face.
constexpr double kRepresentativeOverlap = 0.5;
// A member whose own line of centres is within this cosine of its cluster's
// normal measures the cluster's separation; more tilted pairs would project
// to a false penetration on curved contacts.
constexpr double kAlignedCosine = 0.95;
// Members whose sphere overlap is within this fraction of the cluster's
// deepest give the cluster's normal.
constexpr double kDeepBand = 0.1;

// Each cluster's separation: the least of `along(candidate, cluster)` over
// the members whose own normal is within kAlignedCosine of the cluster's; a
// cluster with none keeps its representative's separation.
template <typename Along>
void leastAlignedSeparations(const std::vector<ContactCandidate>& candidates, const std::vector<int>& reps,
                             const std::vector<Vec3>& normals, const Along& along, std::vector<double>& separations) {
  separations.assign(reps.size(), std::numeric_limits<double>::infinity());
  for (const ContactCandidate& c : candidates) {
    const std::size_t r = static_cast<std::size_t>(c.cluster);
    if (c.normal.dot(normals[r]) < kAlignedCosine) continue;
    separations[r] = std::min(separations[r], along(c, r));
  }
  for (std::size_t r = 0; r < reps.size(); ++r) {
    if (!std::isfinite(separations[r])) separations[r] = candidates[static_cast<std::size_t>(reps[r])].separation;
  }
}

// Unit direction a -> b: the line of centres, else the body centres, else +Z.
Vec3 directionOf(const Vec3& delta, const Vec3& body_a, const Vec3& body_b) {
  const double length = delta.norm();
  if (length > 0.0 && std::isfinite(length)) return delta / length;
  const Vec3 between = body_b - body_a;
  const double between_length = between.norm();
  if (between_length > 0.0 && std::isfinite(between_length)) return between / between_length;
  return Vec3::UnitZ();
}

// A node's voxel box in the world: its centre, and its extent along a world
// direction (the sphere's cube without bounds).
Vec3 boxCentre(const ShapeBounds* bounds, const Mat3& rot, const Vec3& centre, std::int32_t node) {
  return bounds != nullptr ? Vec3(centre + rot * bounds->box_offset[static_cast<std::size_t>(node)]) : centre;
}

// Extent of a node's voxel box along a direction given in its body frame.
double boxExtent(const ShapeBounds* bounds, const SphereTree& tree, std::int32_t node, const Vec3& dir_body) {
  if (bounds == nullptr) return tree.node(node).radius;
  return bounds->box_half[static_cast<std::size_t>(node)].dot(dir_body.cwiseAbs());
}

// A node's voxel box (body frame) and its sphere's radius, read once for the
// six face axes. Without bounds the box is the sphere's cube: every support is r.
struct NodeBox {
  Vec3 offset = Vec3::Zero(), half = Vec3::Zero();
  double radius = 0.0;
  bool has_box = false;
  // Support towards sign x its own axis `axis`: what ShapeBounds::support gives that unit axis.
  double along(int axis, double sign) const {
    return has_box ? std::min(radius, sign * offset[axis] + half[axis]) : radius;
  }
  // Support towards a direction whose offset . dir and half . |dir| are given (ShapeBounds::support).
  double towards(double offset_along, double half_along) const {
    return has_box ? std::min(radius, offset_along + half_along) : radius;
  }
};

NodeBox nodeBox(const ShapeBounds* bounds, const SphereTree& tree, std::int32_t node) {
  NodeBox box;
  box.radius = tree.node(node).radius;
  if (bounds != nullptr) {
    box.offset = bounds->box_offset[static_cast<std::size_t>(node)];
    box.half = bounds->box_half[static_cast<std::size_t>(node)];
    box.has_box = true;
  }
  return box;
}

}  // namespace

PairGeometry::PairGeometry(const PairTest& test, const BodySurface& a, const BodySurface& b)
    : tree_a_(*test.bodyA().tree),
      tree_b_(*test.bodyB().tree),
      bounds_a_(a.bounds),
      bounds_b_(b.bounds),
      covered_a_(a.bounds != nullptr ? a.covered_faces : nullptr),
      covered_b_(b.bounds != nullptr ? b.covered_faces : nullptr),
      rot_a_(test.bodyA().pose->orientation.toRotationMatrix()),
      rot_b_(test.bodyB().pose->orientation.toRotationMatrix()),
      b_in_a_(rot_a_.transpose() * rot_b_),
      a_in_b_(b_in_a_.transpose()),
      abs_b_in_a_(b_in_a_.cwiseAbs()),
      abs_a_in_b_(a_in_b_.cwiseAbs()),
      pos_a_(test.bodyA().pose->position),
      pos_b_(test.bodyB().pose->position) {}

inline double PairGeometry::localSupportA(std::int32_t node, const Vec3& dir_a) const {
  return bounds_a_ != nullptr ? bounds_a_->support(node, dir_a) : tree_a_.node(node).radius;
}

inline double PairGeometry::localSupportB(std::int32_t node, const Vec3& dir_b) const {
  return bounds_b_ != nullptr ? bounds_b_->support(node, dir_b) : tree_b_.node(node).radius;
}

ContactCandidate PairGeometry::candidate(std::int32_t node_a, std::int32_t node_b) const {
  const SphereNode& sa = tree_a_.node(node_a);
  const SphereNode& sb = tree_b_.node(node_b);
  ContactCandidate c;
  c.ca = rot_a_ * sa.centre + pos_a_;
  c.cb = rot_b_ * sb.centre + pos_b_;
  c.node_a = node_a;
  c.node_b = node_b;
  const Vec3 delta = c.cb - c.ca;
  const double reach = sa.radius + sb.radius;
  c.normal = directionOf(delta, pos_a_, pos_b_);  // paper: the line of centres
  c.point = reach > 0.0 ? Vec3(c.ca + delta * (sa.radius / reach)) : Vec3(0.5 * (c.ca + c.cb));
  c.overlap = reach - delta.norm();
  return c;
}

double PairGeometry::gapAlong(const ContactCandidate& c, const Axis& n) const {
  return (c.cb - c.ca).dot(n.world) - localSupportA(c.node_a, n.in_a) - localSupportB(c.node_b, n.reversed_in_b);
}

const PairGeometry::FaceFrame& PairGeometry::faceFrame(const Vec3& normal) const {
  if (face_frame_.valid && face_frame_.normal == normal) return face_frame_;
  FaceFrame& f = face_frame_;
  f.valid = true;
  f.normal = normal;
  tangentBasis(normal, f.tangent[0], f.tangent[1]);
  f.across = axis(normal);
  for (int k = 0; k < 2; ++k) {
    f.tangent_in_a[k] = rot_a_.transpose() * f.tangent[k];
    f.tangent_in_b[k] = rot_b_.transpose() * f.tangent[k];
  }
  return f;
}

// Face-on, the contact is where the two boxes' faces overlap: the middle of
// their projections on the face plane, halfway between the surfaces (the
// Fig. 4 point would sit off to the side of a ball resting on a large leaf).
Vec3 PairGeometry::faceContactPoint(const ContactCandidate& c) const {
  const Vec3 ba = boxCentre(bounds_a_, rot_a_, c.ca, c.node_a);
  const Vec3 bb = boxCentre(bounds_b_, rot_b_, c.cb, c.node_b);
  const FaceFrame& f = faceFrame(c.normal);
  const Vec3& t1 = f.tangent[0];
  const Vec3& t2 = f.tangent[1];
  Vec3 point = 0.5 * ((c.ca + localSupportA(c.node_a, f.across.in_a) * c.normal) +
                      (c.cb - localSupportB(c.node_b, f.across.reversed_in_b) * c.normal));
  point -= point.dot(t1) * t1 + point.dot(t2) * t2;
  for (int k = 0; k < 2; ++k) {
    const Vec3& t = f.tangent[k];
    const double ea = boxExtent(bounds_a_, tree_a_, c.node_a, f.tangent_in_a[k]);
    const double eb = boxExtent(bounds_b_, tree_b_, c.node_b, f.tangent_in_b[k]);
    const double lo = std::max(ba.dot(t) - ea, bb.dot(t) - eb);
    const double hi = std::min(ba.dot(t) + ea, bb.dot(t) + eb);
    point += 0.5 * (lo + hi) * t;
  }
  return point;
}

namespace {

// A mask's covered faces a direction (body frame, outward from the node) points through.
bool throughCovered(std::uint8_t mask, const Vec3& outward) {
  constexpr double kAlong = 1e-6;  // a component this small is across the face, not through it
  for (int axis = 0; axis < 3; ++axis) {
    if (outward[axis] > kAlong && (mask & faceBit(axis, true)) != 0) return true;
    if (outward[axis] < -kAlong && (mask & faceBit(axis, false)) != 0) return true;
  }
  return false;
}

// `outward` without its components through covered faces (zero when nothing is left).
Vec3 clipCovered(std::uint8_t mask, Vec3 outward) {
  for (int axis = 0; axis < 3; ++axis) {
    if ((outward[axis] > 0.0 && (mask & faceBit(axis, true)) != 0) ||
        (outward[axis] < 0.0 && (mask & faceBit(axis, false)) != 0)) {
      outward[axis] = 0.0;
    }
  }
  return outward;
}

}  // namespace

bool PairGeometry::intoCover(std::uint8_t mask_a, std::uint8_t mask_b, const Vec3& n) const {
  return (mask_a != 0 && throughCovered(mask_a, rot_a_.transpose() * n)) ||
         (mask_b != 0 && throughCovered(mask_b, -(rot_b_.transpose() * n)));
}

Vec3 PairGeometry::awayFromCover(std::uint8_t mask_a, std::uint8_t mask_b, const Vec3& n) const {
  Vec3 open = n;
  if (mask_a != 0) open = rot_a_ * clipCovered(mask_a, rot_a_.transpose() * open);
  if (mask_b != 0) open = -(rot_b_ * clipCovered(mask_b, -(rot_b_.transpose() * open)));
  const double length = open.norm();
  return length > 1e-9 ? Vec3(open / length) : n;
}

void PairGeometry::refine(ContactCandidate& c, bool face_normals) const {
  // A normal through a face another static body covers would push b into
  // that body (a tile's rim, into the next tile): its part along the face goes.
  const std::uint8_t mask_a = covered_a_ != nullptr ? covered_a_[static_cast<std::size_t>(c.node_a)] : 0;
  const std::uint8_t mask_b = covered_b_ != nullptr ? covered_b_[static_cast<std::size_t>(c.node_b)] : 0;
  const bool any_cover = (mask_a | mask_b) != 0;
  const bool covered = any_cover && intoCover(mask_a, mask_b, c.normal);
  if (covered) c.normal = awayFromCover(mask_a, mask_b, c.normal);
  c.separation = gapAlong(c, c.normal);
  c.refined = true;
  if (!face_normals || (bounds_a_ == nullptr && bounds_b_ == nullptr)) return;
  // A face axis of either voxel box that separates the nodes more than the
  // line of centres is the better normal (separating-axis rule): face-on,
  // the line of centres of two voxel spheres tilts by up to 45 deg.
  bool face = false;
  const Vec3 delta = c.cb - c.ca;
  const Vec3 delta_a = rot_a_.transpose() * delta;
  const Vec3 delta_b = b_in_a_.transpose() * delta_a;
  const double better_by = 1e-12 * std::abs(c.overlap + delta.norm());  // more than rounding
  // Each node's box read once. Along +-axis k of one box the other box's
  // support is min(r, -+offset . axis + half . |axis|): the dot products of
  // the six axes are four 3 x 3 products. Each is a transposed product, which
  // Eigen sums as the dot product of a column, as support() does.
  const NodeBox box_a = nodeBox(bounds_a_, tree_a_, c.node_a);
  const NodeBox box_b = nodeBox(bounds_b_, tree_b_, c.node_b);
  const Vec3 offset_b_in_a = a_in_b_.transpose() * box_b.offset;  // B's box offset along A's axes
  const Vec3 half_b_in_a = abs_a_in_b_.transpose() * box_b.half;   // B's half extent along A's axes
  const Vec3 offset_a_in_b = b_in_a_.transpose() * box_a.offset;
  const Vec3 half_a_in_b = abs_b_in_a_.transpose() * box_a.half;
  for (int k = 0; k < 6; ++k) {
    // Axis k of A (k < 3) or of B, pointing from a to b, in both frames.
    const bool of_a = k < 3;
    const int box_axis = of_a ? k : k - 3;
    const double along = of_a ? delta_a[box_axis] : delta_b[box_axis];
    double sign = along < 0.0 ? -1.0 : 1.0;
    const auto normalOf = [&] { return Vec3(sign * (of_a ? Vec3(rot_a_.col(box_axis)) : Vec3(rot_b_.col(box_axis)))); };
    if (any_cover && intoCover(mask_a, mask_b, normalOf())) {
      // b's node lies beyond the covered side (deeper than a one-sided
      // wall's middle): the open side of the axis is the way out, however deep.
      sign = -sign;
      if (intoCover(mask_a, mask_b, normalOf())) continue;
    }
    // The node whose own axis this is reads its support straight off its box.
    const double g = of_a ? sign * along - box_a.along(box_axis, sign) -
                                box_b.towards(-sign * offset_b_in_a[box_axis], half_b_in_a[box_axis])
                          : sign * along - box_a.towards(sign * offset_a_in_b[box_axis], half_a_in_b[box_axis]) -
                                box_b.along(box_axis, -sign);
    // Under cover the line of centres was bent: any open face axis is the better normal.
    if (g > c.separation + better_by || (covered && !face)) {
      c.separation = g;
      c.normal = normalOf();
      face = true;
    }
  }
  if (face) c.point = faceContactPoint(c);
}

void PairGeometry::leavesInside(bool from_a, const InteriorField& into, std::vector<std::int32_t>& stack,
                                std::vector<ContactCandidate>& out) const {
  const SphereTree& tree = from_a ? tree_a_ : tree_b_;
  const ShapeBounds* bounds = from_a ? bounds_a_ : bounds_b_;
  const Mat3& rot_from = from_a ? rot_a_ : rot_b_;
  const Mat3& rot_into = from_a ? rot_b_ : rot_a_;
  const Mat3& to_into = from_a ? a_in_b_ : b_in_a_;  // from's axes in into's frame
  const Vec3& pos_from = from_a ? pos_a_ : pos_b_;
  const Vec3& pos_into = from_a ? pos_b_ : pos_a_;
  const Vec3 offset = rot_into.transpose() * (pos_from - pos_into);
  // A static body's faces that others cover are no way out (a tile's rim, into the next tile).
  const std::uint8_t* covered = from_a ? covered_b_ : covered_a_;
  const std::uint8_t root_mask = covered != nullptr ? covered[0] : 0;
  // The probe's outside distance is of the nearest occupied voxel to the
  // centre's cell, not to the centre: within a voxel's diagonal.
  const double slack = std::sqrt(3.0) * into.voxelSize();
  stack.clear();
  stack.push_back(0);
  while (!stack.empty()) {
    const std::int32_t n = stack.back();
    stack.pop_back();
    const SphereNode& node = tree.node(n);
    const InteriorProbe probe = into.probe(to_into * node.centre + offset);
    if (!probe.inside && -probe.depth > node.radius + slack) continue;  // wholly outside the solid
    if (!tree.isLeaf(n)) {
      for (std::int32_t k = 0; k < node.child_count; ++k) stack.push_back(node.first_child + k);
      continue;
    }
    if (!probe.inside) continue;
    Vec3 way = probe.out;
    if (root_mask != 0) {
      way = clipCovered(root_mask, way);
      const double length = way.norm();
      if (!(length > 1e-9)) continue;
      way /= length;
    }
    const Vec3 out_world = rot_into * way;  // the way `from` must move
    // How far the leaf's voxel box reaches past its centre, deeper in.
    const Vec3 deeper_from = rot_from.transpose() * (-out_world);
    const double reach = bounds != nullptr ? bounds->support(n, deeper_from) : node.radius;
    const Vec3 centre = rot_from * node.centre + pos_from;
    ContactCandidate c;
    c.ca = c.cb = centre;
    c.node_a = from_a ? n : kInteriorNode;
    c.node_b = from_a ? kInteriorNode : n;
    c.normal = from_a ? Vec3(-out_world) : out_world;  // a -> b
    c.overlap = probe.depth + reach;
    c.separation = -c.overlap;
    // Halfway between the leaf's deepest point and the way out.
    c.point = centre + 0.5 * (probe.depth - reach) * out_world;
    c.refined = true;
    out.push_back(c);
  }
}

void PairGeometry::interiorCandidates(const InteriorField& field_a, const InteriorField& field_b,
                                      std::vector<std::int32_t>& stack, std::vector<ContactCandidate>& out) const {
  out.clear();
  leavesInside(true, field_b, stack, out);
  leavesInside(false, field_a, stack, out);
}

bool interiorContacts(const PairGeometry& geometry, const InteriorField& field_a, const InteriorField& field_b,
                      int limit, std::vector<std::int32_t>& stack, std::vector<ContactCandidate>& candidates,
                      std::vector<int>& reps, std::vector<Vec3>& normals, std::vector<double>& separations) {
  geometry.interiorCandidates(field_a, field_b, stack, candidates);
  if (candidates.empty()) return false;
  CandidateSpread spread;
  spread.centroid.setZero();
  for (const ContactCandidate& c : candidates) spread.centroid += c.point;
  spread.centroid /= static_cast<double>(candidates.size());
  spread.scale = std::min(field_a.voxelSize(), field_b.voxelSize());
  pickRepresentatives(candidates, deepestOverlap(candidates), limit, spread, reps);
  clusterNormals(candidates, reps, normals);
  // A member's separation is already its depth along its own way out.
  leastAlignedSeparations(candidates, reps, normals,
                          [](const ContactCandidate& c, std::size_t) { return c.separation; }, separations);
  return true;
}

void gatherCandidates(const PairTest& test, const PairGeometry& geometry, std::vector<ContactCandidate>& out) {
  out.clear();
  if (test.hasLastPair()) {
    for (const SpherePair& p : test.lastPairs()) out.push_back(geometry.candidate(p.a, p.b));
  } else {
    out.push_back(geometry.candidate(0, 0));
  }
}

double deepestOverlap(const std::vector<ContactCandidate>& candidates) {
  double deepest = -std::numeric_limits<double>::infinity();
  for (const ContactCandidate& c : candidates) deepest = std::max(deepest, c.overlap);
  return deepest;
}

void refineDeepCandidates(std::vector<ContactCandidate>& candidates, double deepest, const PairGeometry& geometry,
                          bool face_normals) {
  // The shallow ones only join clusters: skipping them halves the work on a
  // face of leaf spheres.
  const double deep_enough = deepest > 0.0 ? kRepresentativeOverlap * deepest : deepest;
  for (ContactCandidate& c : candidates) {
    if (c.overlap >= deep_enough) geometry.refine(c, face_normals);
  }
}

void dropShallowCandidates(std::vector<ContactCandidate>& candidates) {
  candidates.erase(std::remove_if(candidates.begin(), candidates.end(),
                                  [](const ContactCandidate& c) { return !c.refined; }),
                   candidates.end());
}

namespace {

// A candidate nearer to a representative `at` (number `cluster`) than to
// those before it joins its cluster (a tie stays with the earlier one).
inline void joinIfNearer(ContactCandidate& c, const Vec3& at, int cluster) {
  const double d = (c.point - at).squaredNorm();
  if (d < c.nearest) {
    c.nearest = d;
    c.cluster = cluster;
  }
}

// Candidate `rep` becomes representative number `cluster`.
void joinRepresentative(std::vector<ContactCandidate>& candidates, int rep, int cluster) {
  const Vec3 at = candidates[static_cast<std::size_t>(rep)].point;
  for (ContactCandidate& c : candidates) joinIfNearer(c, at, cluster);
}

}  // namespace

CandidateSpread spreadOf(const std::vector<ContactCandidate>& candidates) {
  CandidateSpread spread;
  if (candidates.empty()) return spread;
  for (const ContactCandidate& c : candidates) {
    spread.centroid += c.point;
    spread.scale = std::min(spread.scale, c.overlap + (c.cb - c.ca).norm());
  }
  spread.centroid /= static_cast<double>(candidates.size());
  return spread;
}

void pickRepresentatives(std::vector<ContactCandidate>& candidates, double deepest, int limit,
                         std::vector<int>& reps) {
  pickRepresentatives(candidates, deepest, limit, spreadOf(candidates), reps);
}

void pickRepresentatives(std::vector<ContactCandidate>& candidates, double deepest, int limit,
                         const CandidateSpread& spread, std::vector<int>& reps) {
  reps.clear();
  if (candidates.empty()) return;
  limit = std::clamp(limit, 1, kMaxRepresentatives);
  for (ContactCandidate& c : candidates) c.nearest = std::numeric_limits<double>::infinity();
  const Vec3& centroid = spread.centroid;
  const double scale = spread.scale;     // smallest reach: the length unit
  const double tie = 1e-3 * scale;      // overlaps this close count as equal
  const double distinct = 1e-6 * scale;  // points closer than this are one point

  // First: among the deepest (within `tie`), the one farthest from the centroid
  // (a corner), so the choice does not flicker between equal pairs.
  {
    int best = -1;
    double best_far = -1.0;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const ContactCandidate& c = candidates[i];
      if (c.overlap < deepest - tie) continue;
      const double far = (c.point - centroid).squaredNorm();
      if (far > best_far) {
        best_far = far;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) return;  // `deepest` is not of these candidates
    reps.push_back(best);
  }
  // Then: farthest from the first; largest triangle; then farthest from all
  // chosen. `nearest` is each candidate's squared distance to the chosen ones:
  // the newest one is joined in the pass that scores the next (a pass less each).
  while (static_cast<int>(reps.size()) < limit) {
    const Vec3 newest = candidates[static_cast<std::size_t>(reps.back())].point;
    const int newest_cluster = static_cast<int>(reps.size()) - 1;
    int best = -1;
    double best_score = distinct * distinct;
    const Vec3 p0 = candidates[reps[0]].point;
    Vec3 axis = Vec3::Zero();
    if (reps.size() == 2) {
      axis = candidates[reps[1]].point - p0;
      axis.normalize();
    }
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      ContactCandidate& c = candidates[i];
      joinIfNearer(c, newest, newest_cluster);
      if (!c.refined || c.nearest <= distinct * distinct) continue;
      const double score = reps.size() == 2 ? (c.point - p0).cross(axis).squaredNorm() : c.nearest;
      if (score > best_score) {
        best_score = score;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) return;  // every candidate joined the chosen ones
    reps.push_back(best);
  }
  joinRepresentative(candidates, reps.back(), static_cast<int>(reps.size()) - 1);
}

void assignClusters(std::vector<ContactCandidate>& candidates, const std::vector<int>& reps) {
  for (ContactCandidate& c : candidates) c.nearest = std::numeric_limits<double>::infinity();
  for (std::size_t r = 0; r < reps.size(); ++r) joinRepresentative(candidates, reps[r], static_cast<int>(r));
}

void clusterNormals(const std::vector<ContactCandidate>& candidates, const std::vector<int>& reps,
                    std::vector<Vec3>& normals) {
  // A voxel resting on one floor voxel also touches the next one edge-on,
  // which says nothing about the direction of this contact.
  const std::size_t count = reps.size();
  normals.resize(count);
  if (count == 0) return;
  double deepest[kMaxRepresentatives];
  Vec3 sum[kMaxRepresentatives];
  for (std::size_t r = 0; r < count; ++r) {
    deepest[r] = -std::numeric_limits<double>::infinity();
    sum[r].setZero();
  }
  for (const ContactCandidate& c : candidates) {
    double& d = deepest[static_cast<std::size_t>(c.cluster)];
    d = std::max(d, c.overlap);
  }
  for (const ContactCandidate& c : candidates) {
    const std::size_t r = static_cast<std::size_t>(c.cluster);
    if (!c.refined || c.overlap < deepest[r] - kDeepBand * std::abs(deepest[r])) continue;
    sum[r] += c.normal;
  }
  for (std::size_t r = 0; r < count; ++r) {
    const double sum_norm = sum[r].norm();
    normals[r] = sum_norm > 0.0 && std::isfinite(sum_norm) ? Vec3(sum[r] / sum_norm)
                                                            : candidates[static_cast<std::size_t>(reps[r])].normal;
  }
}

void clusterSeparations(const std::vector<ContactCandidate>& candidates, const std::vector<int>& reps,
                        const std::vector<Vec3>& normals, const PairGeometry& geometry,
                        std::vector<double>& separations) {
  PairGeometry::Axis axes[kMaxRepresentatives];
  for (std::size_t r = 0; r < reps.size(); ++r) axes[r] = geometry.axis(normals[r]);
  leastAlignedSeparations(candidates, reps, normals,
                          [&](const ContactCandidate& c, std::size_t r) { return geometry.gapAlong(c, axes[r]); },
                          separations);
}

void ContactBuilder::append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b,
                            double priority, const BodySurface& a, const BodySurface& b,
                            const ContactBuildOptions& options, std::vector<Contact>& out) {
  const PairStatus status = test.status();
  const bool solids = a.interior != nullptr && b.interior != nullptr && a.interior->built() && b.interior->built();
  if (status == PairStatus::Separate) {
    // Surfaces apart, but one body may lie wholly inside the other.
    if (solids && nested(test, *a.interior, *b.interior)) {
      const PairGeometry geometry(test, a, b);
      if (interiorContacts(geometry, *a.interior, *b.interior, options.max_contacts_per_pair, stack_, candidates_,
                           reps_, normals_, separations_)) {
        emit(test, true, index_a, index_b, priority, out);  // the field measured it: proven
      }
    }
    return;
  }
  if (status == PairStatus::Unresolved && !options.accept_unresolved) return;

  const PairGeometry geometry(test, a, b);
  gatherCandidates(test, geometry, candidates_);
  const double deepest = deepestOverlap(candidates_);
  refineDeepCandidates(candidates_, deepest, geometry, options.face_normals);
  // Measured before the shallow ones go: the first pick among a face's equally
  // far corners is left to rounding, and it orders the solver's rows.
  const CandidateSpread spread = spreadOf(candidates_);
  dropShallowCandidates(candidates_);
  pickRepresentatives(candidates_, deepest, options.max_contacts_per_pair, spread, reps_);  // and assigns the clusters

  clusterNormals(candidates_, reps_, normals_);
  clusterSeparations(candidates_, reps_, normals_, geometry, separations_);
  // Only a pair resolved at the leaves: an unresolved pair's overlap is its
  // frontier's, not proven of its surfaces (see emit).
  if (status == PairStatus::Colliding && solids) {
    const double least = separations_.empty() ? 0.0 : *std::min_element(separations_.begin(), separations_.end());
    const double voxel = std::min(a.interior->voxelSize(), b.interior->voxelSize());
    if (least < -kInteriorDepth * voxel &&
        interiorContacts(geometry, *a.interior, *b.interior, options.max_contacts_per_pair, stack_, inside_, reps_,
                         normals_, separations_)) {
      candidates_.swap(inside_);
    }
  }
  emit(test, status == PairStatus::Colliding, index_a, index_b, priority, out);
}

bool ContactBuilder::nested(const PairTest& test, const InteriorField& field_a, const InteriorField& field_b) {
  // The root sphere's centre of the smaller body, in the larger one's solid.
  const PairBody& a = test.bodyA();
  const PairBody& b = test.bodyB();
  const bool a_smaller = a.tree->node(0).radius <= b.tree->node(0).radius;
  const PairBody& inner = a_smaller ? a : b;
  const PairBody& outer = a_smaller ? b : a;
  const Vec3 centre = inner.pose->orientation * inner.tree->node(0).centre + inner.pose->position;
  const Vec3 in_outer = outer.pose->orientation.conjugate() * (centre - outer.pose->position);
  return (a_smaller ? field_b : field_a).probe(in_outer).inside;
}

void ContactBuilder::emit(const PairTest& test, bool proven, std::uint32_t index_a, std::uint32_t index_b,
                          double priority, std::vector<Contact>& out) const {
  for (std::size_t r = 0; r < reps_.size(); ++r) {
    const ContactCandidate& rep = candidates_[reps_[r]];
    Contact contact;
    contact.a = test.bodyA().id;
    contact.b = test.bodyB().id;
    contact.index_a = index_a;
    contact.index_b = index_b;
    contact.point = rep.point;
    contact.normal = normals_[r];
    contact.depth = std::max(0.0, rep.overlap);
    // An unresolved pair's overlap is its frontier's, not proven of its
    // surfaces (they may be up to its gap bound apart): its contact keeps the
    // bodies from closing in but pushes nothing apart. Pushed out of their
    // root spheres' and node boxes' overlaps, the rocks of a pile under a tick
    // budget flowed and flattened it (docs/error_vs_runtime.md).
    contact.separation = proven ? separations_[r] : std::max(0.0, separations_[r]);
    // The pair's bound (its deepest sphere pair's h_a + h_b), the same for
    // every point: the solver's slop is a fraction of it, and a slop that
    // differs point by point let position correction lift a rolling link
    // a little every tick (config/meshes.yaml's link rolled off the floor).
    contact.gap_bound = test.gapBound();
    contact.sphere_bound = contact.gap_bound;
    contact.level = std::max(0, test.deepestLevel());
    contact.resolved = proven;
    contact.priority = priority;
    contact.node_a = rep.node_a;
    contact.node_b = rep.node_b;
    out.push_back(contact);
  }
}

}  // namespace stc
