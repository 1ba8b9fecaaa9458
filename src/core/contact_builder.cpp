// Contacts from the intersecting sphere pairs of a PairTest (paper 3.5, Fig. 4).
#include "sphere_tree_collision/contact_builder.hpp"

#include "sphere_tree_collision/contact_solver.hpp"  // tangentBasis
#include "sphere_tree_collision/static_cover.hpp"    // faceBit

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

double boxExtent(const ShapeBounds* bounds, const SphereTree& tree, const Mat3& rot, std::int32_t node,
                 const Vec3& dir) {
  if (bounds == nullptr) return tree.node(node).radius;
  return bounds->box_half[static_cast<std::size_t>(node)].dot((rot.transpose() * dir).cwiseAbs());
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
      pos_a_(test.bodyA().pose->position),
      pos_b_(test.bodyB().pose->position) {}

double PairGeometry::localSupportA(std::int32_t node, const Vec3& dir_a) const {
  return bounds_a_ != nullptr ? bounds_a_->support(node, dir_a) : tree_a_.node(node).radius;
}

double PairGeometry::localSupportB(std::int32_t node, const Vec3& dir_b) const {
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

double PairGeometry::gapAlong(const ContactCandidate& c, const Vec3& n) const {
  return (c.cb - c.ca).dot(n) - supportA(c.node_a, n) - supportB(c.node_b, -n);
}

// Face-on, the contact is where the two boxes' faces overlap: the middle of
// their projections on the face plane, halfway between the surfaces (the
// Fig. 4 point would sit off to the side of a ball resting on a large leaf).
Vec3 PairGeometry::faceContactPoint(const ContactCandidate& c) const {
  const Vec3 ba = boxCentre(bounds_a_, rot_a_, c.ca, c.node_a);
  const Vec3 bb = boxCentre(bounds_b_, rot_b_, c.cb, c.node_b);
  Vec3 t1, t2;
  tangentBasis(c.normal, t1, t2);
  Vec3 point = 0.5 * ((c.ca + supportA(c.node_a, c.normal) * c.normal) +
                      (c.cb - supportB(c.node_b, -c.normal) * c.normal));
  point -= point.dot(t1) * t1 + point.dot(t2) * t2;
  for (const Vec3& t : {t1, t2}) {
    const double ea = boxExtent(bounds_a_, tree_a_, rot_a_, c.node_a, t);
    const double eb = boxExtent(bounds_b_, tree_b_, rot_b_, c.node_b, t);
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
  for (int k = 0; k < 6; ++k) {
    // Axis k of A (k < 3) or of B, pointing from a to b, in both frames.
    const bool of_a = k < 3;
    const int axis = of_a ? k : k - 3;
    const double along = of_a ? delta_a[axis] : delta_b[axis];
    double sign = along < 0.0 ? -1.0 : 1.0;
    Vec3 normal = sign * (of_a ? Vec3(rot_a_.col(axis)) : Vec3(rot_b_.col(axis)));
    if (any_cover && intoCover(mask_a, mask_b, normal)) {
      // b's node lies beyond the covered side (deeper than a one-sided
      // wall's middle): the open side of the axis is the way out, however deep.
      sign = -sign;
      normal = -normal;
      if (intoCover(mask_a, mask_b, normal)) continue;
    }
    const Vec3 dir_a = sign * (of_a ? Vec3(Vec3::Unit(axis)) : Vec3(b_in_a_.col(axis)));
    const Vec3 dir_b = sign * (of_a ? Vec3(b_in_a_.row(axis).transpose()) : Vec3(Vec3::Unit(axis)));
    const double g = sign * along - localSupportA(c.node_a, dir_a) - localSupportB(c.node_b, -dir_b);
    // Under cover the line of centres was bent: any open face axis is the better normal.
    if (g > c.separation + 1e-12 * std::abs(c.overlap + delta.norm()) || (covered && !face)) {
      c.separation = g;
      c.normal = normal;
      face = true;
    }
  }
  if (face) c.point = faceContactPoint(c);
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

void pickRepresentatives(const std::vector<ContactCandidate>& candidates, double deepest, int limit,
                         std::vector<int>& reps) {
  reps.clear();
  if (candidates.empty()) return;
  limit = std::clamp(limit, 1, kMaxRepresentatives);
  Vec3 centroid = Vec3::Zero();
  double scale = std::numeric_limits<double>::infinity();  // smallest reach: the length unit
  for (const ContactCandidate& c : candidates) {
    centroid += c.point;
    scale = std::min(scale, c.overlap + (c.cb - c.ca).norm());
  }
  centroid /= static_cast<double>(candidates.size());
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
  // Then: farthest from the first; largest triangle; then farthest from all chosen.
  while (static_cast<int>(reps.size()) < limit) {
    int best = -1;
    double best_score = distinct * distinct;
    const Vec3 p0 = candidates[reps[0]].point;
    Vec3 axis = Vec3::Zero();
    if (reps.size() == 2) {
      axis = candidates[reps[1]].point - p0;
      axis.normalize();
    }
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const ContactCandidate& c = candidates[i];
      if (!c.refined) continue;
      double nearest = std::numeric_limits<double>::infinity();
      for (int r : reps) nearest = std::min(nearest, (c.point - candidates[r].point).squaredNorm());
      if (nearest <= distinct * distinct) continue;
      double score = nearest;
      if (reps.size() == 1) score = (c.point - p0).squaredNorm();
      if (reps.size() == 2) score = (c.point - p0).cross(axis).squaredNorm();
      if (score > best_score) {
        best_score = score;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    reps.push_back(best);
  }
}

void assignClusters(std::vector<ContactCandidate>& candidates, const std::vector<int>& reps) {
  for (ContactCandidate& c : candidates) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t r = 0; r < reps.size(); ++r) {
      const double d = (c.point - candidates[reps[r]].point).squaredNorm();
      if (d < nearest) {
        nearest = d;
        c.cluster = static_cast<int>(r);
      }
    }
  }
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
  const std::size_t count = reps.size();
  separations.assign(count, std::numeric_limits<double>::infinity());
  for (const ContactCandidate& c : candidates) {
    const std::size_t r = static_cast<std::size_t>(c.cluster);
    if (c.normal.dot(normals[r]) < kAlignedCosine) continue;
    separations[r] = std::min(separations[r], geometry.gapAlong(c, normals[r]));
  }
  for (std::size_t r = 0; r < count; ++r) {
    if (!std::isfinite(separations[r])) separations[r] = candidates[static_cast<std::size_t>(reps[r])].separation;
  }
}

void ContactBuilder::append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b,
                            double priority, const BodySurface& a, const BodySurface& b,
                            const ContactBuildOptions& options, std::vector<Contact>& out) {
  const PairStatus status = test.status();
  if (status == PairStatus::Separate) return;
  if (status == PairStatus::Unresolved && !options.accept_unresolved) return;

  const PairGeometry geometry(test, a, b);
  gatherCandidates(test, geometry, candidates_);
  const double deepest = deepestOverlap(candidates_);
  refineDeepCandidates(candidates_, deepest, geometry, options.face_normals);
  pickRepresentatives(candidates_, deepest, options.max_contacts_per_pair, reps_);
  assignClusters(candidates_, reps_);

  clusterNormals(candidates_, reps_, normals_);
  clusterSeparations(candidates_, reps_, normals_, geometry, separations_);
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
    contact.separation = separations_[r];
    // The pair's bound (its deepest sphere pair's h_a + h_b), the same for
    // every point: the solver's slop is a fraction of it, and a slop that
    // differs point by point let position correction lift a rolling link
    // a little every tick (config/meshes.yaml's link rolled off the floor).
    contact.gap_bound = test.gapBound();
    contact.level = std::max(0, test.deepestLevel());
    contact.resolved = status == PairStatus::Colliding;
    contact.priority = priority;
    contact.node_a = rep.node_a;
    contact.node_b = rep.node_b;
    out.push_back(contact);
  }
}

}  // namespace stc
