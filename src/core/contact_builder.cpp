// Contacts from the intersecting sphere pairs of a PairTest (paper 3.5, Fig. 4).
#include "sphere_tree_collision/contact_builder.hpp"

#include "sphere_tree_collision/contact_solver.hpp"  // tangentBasis

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

}  // namespace

void ContactBuilder::append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b,
                            double priority, const ShapeBounds* bounds_a,
                            const ShapeBounds* bounds_b, const ContactBuildOptions& options,
                            std::vector<Contact>& out) {
  const PairStatus status = test.status();
  if (status == PairStatus::Separate) return;
  if (status == PairStatus::Unresolved && !options.accept_unresolved) return;
  const bool resolved = status == PairStatus::Colliding;

  const PairBody& body_a = test.bodyA();
  const PairBody& body_b = test.bodyB();
  const SphereTree& tree_a = *body_a.tree;
  const SphereTree& tree_b = *body_b.tree;
  const Mat3 rot_a = body_a.pose->orientation.toRotationMatrix();
  const Mat3 rot_b = body_b.pose->orientation.toRotationMatrix();
  const Vec3& pos_a = body_a.pose->position;
  const Vec3& pos_b = body_b.pose->position;

  // Surface of a node towards a direction given in its own body frame: its
  // voxel box within its sphere, or the sphere alone without bounds.
  const auto local_support_a = [&](std::int32_t node, const Vec3& dir_a) {
    return bounds_a != nullptr ? bounds_a->support(node, dir_a) : tree_a.node(node).radius;
  };
  const auto local_support_b = [&](std::int32_t node, const Vec3& dir_b) {
    return bounds_b != nullptr ? bounds_b->support(node, dir_b) : tree_b.node(node).radius;
  };
  const auto support_a = [&](std::int32_t node, const Vec3& dir) {
    return local_support_a(node, rot_a.transpose() * dir);
  };
  const auto support_b = [&](std::int32_t node, const Vec3& dir) {
    return local_support_b(node, rot_b.transpose() * dir);
  };
  // Gap between the two nodes' surfaces along unit n (a -> b).
  const auto gap_along = [&](const Candidate& c, const Vec3& n) {
    return (c.cb - c.ca).dot(n) - support_a(c.node_a, n) - support_b(c.node_b, -n);
  };
  const Mat3 b_in_a = rot_a.transpose() * rot_b;  // B's axes in A's frame (columns)

  // Node boxes in the world: centre and extent along a world direction.
  const auto box_centre = [](const ShapeBounds* bounds, const Mat3& rot, const Vec3& centre,
                             std::int32_t node) {
    return bounds != nullptr ? Vec3(centre + rot * bounds->box_offset[static_cast<std::size_t>(node)]) : centre;
  };
  const auto box_extent = [](const ShapeBounds* bounds, const SphereTree& tree, const Mat3& rot,
                             std::int32_t node, const Vec3& dir) {
    if (bounds == nullptr) return tree.node(node).radius;
    return bounds->box_half[static_cast<std::size_t>(node)].dot((rot.transpose() * dir).cwiseAbs());
  };
  const auto faceContactPoint = [&](const Candidate& c) {
    const Vec3 ba = box_centre(bounds_a, rot_a, c.ca, c.node_a);
    const Vec3 bb = box_centre(bounds_b, rot_b, c.cb, c.node_b);
    Vec3 t1, t2;
    tangentBasis(c.normal, t1, t2);
    Vec3 point = 0.5 * ((c.ca + support_a(c.node_a, c.normal) * c.normal) +
                        (c.cb - support_b(c.node_b, -c.normal) * c.normal));
    point -= point.dot(t1) * t1 + point.dot(t2) * t2;
    for (const Vec3& t : {t1, t2}) {
      const double ea = box_extent(bounds_a, tree_a, rot_a, c.node_a, t);
      const double eb = box_extent(bounds_b, tree_b, rot_b, c.node_b, t);
      const double lo = std::max(ba.dot(t) - ea, bb.dot(t) - eb);
      const double hi = std::min(ba.dot(t) + ea, bb.dot(t) + eb);
      point += 0.5 * (lo + hi) * t;
    }
    return point;
  };

  // 1. Candidates: every intersecting sphere pair (the roots before any test).
  candidates_.clear();
  const auto add = [&](std::int32_t na, std::int32_t nb) {
    const SphereNode& sa = tree_a.node(na);
    const SphereNode& sb = tree_b.node(nb);
    Candidate c;
    c.ca = rot_a * sa.centre + pos_a;
    c.cb = rot_b * sb.centre + pos_b;
    c.node_a = na;
    c.node_b = nb;
    const Vec3 delta = c.cb - c.ca;
    const double reach = sa.radius + sb.radius;
    c.normal = directionOf(delta, pos_a, pos_b);  // paper: the line of centres
    c.point = reach > 0.0 ? Vec3(c.ca + delta * (sa.radius / reach)) : Vec3(0.5 * (c.ca + c.cb));
    c.overlap = reach - delta.norm();
    candidates_.push_back(c);
  };
  if (test.hasLastPair()) {
    for (const SpherePair& p : test.lastPairs()) add(p.a, p.b);
  } else {
    add(0, 0);
  }
  double deepest = -std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates_) deepest = std::max(deepest, c.overlap);
  const double deep_enough = deepest > 0.0 ? kRepresentativeOverlap * deepest : deepest;
  // Separation and normal of a deep candidate (the shallow ones only join
  // clusters: skipping them halves the work on a face of leaf spheres).
  const auto refine = [&](Candidate& c) {
    c.separation = gap_along(c, c.normal);
    c.refined = true;
    if (options.face_normals && (bounds_a != nullptr || bounds_b != nullptr)) {
      // A face axis of either voxel box that separates the nodes more than
      // the line of centres is the better normal (separating-axis rule):
      // face-on, the line of centres of two voxel spheres tilts by up to 45 deg.
      bool face = false;
      const Vec3 delta = c.cb - c.ca;
      const Vec3 delta_a = rot_a.transpose() * delta;
      const Vec3 delta_b = b_in_a.transpose() * delta_a;
      for (int k = 0; k < 6; ++k) {
        // Axis k of A (k < 3) or of B, pointing from a to b, in both frames.
        const bool of_a = k < 3;
        const int axis = of_a ? k : k - 3;
        const double along = of_a ? delta_a[axis] : delta_b[axis];
        const double sign = along < 0.0 ? -1.0 : 1.0;
        const Vec3 dir_a = sign * (of_a ? Vec3(Vec3::Unit(axis)) : Vec3(b_in_a.col(axis)));
        const Vec3 dir_b = sign * (of_a ? Vec3(b_in_a.row(axis).transpose()) : Vec3(Vec3::Unit(axis)));
        const double g = std::abs(along) - local_support_a(c.node_a, dir_a) - local_support_b(c.node_b, -dir_b);
        if (g > c.separation + 1e-12 * std::abs(c.overlap + delta.norm())) {
          c.separation = g;
          c.normal = sign * (of_a ? Vec3(rot_a.col(axis)) : Vec3(rot_b.col(axis)));
          face = true;
        }
      }
      // Face-on, the contact is where the two boxes' faces overlap: the
      // middle of their projections on the face plane, halfway between the
      // surfaces (the Fig. 4 point would sit off to the side of a ball
      // resting on a large leaf).
      if (face) c.point = faceContactPoint(c);
    }
  };
  for (Candidate& c : candidates_) {
    if (c.overlap >= deep_enough) refine(c);
  }

  // 2. Representatives, spread out among the deep candidates.
  const int limit = std::clamp(options.max_contacts_per_pair, 1, 16);
  Vec3 centroid = Vec3::Zero();
  double scale = std::numeric_limits<double>::infinity();  // smallest reach: the length unit
  for (const Candidate& c : candidates_) {
    centroid += c.point;
    scale = std::min(scale, c.overlap + (c.cb - c.ca).norm());
  }
  centroid /= static_cast<double>(candidates_.size());
  const double tie = 1e-3 * scale;      // overlaps this close count as equal
  const double distinct = 1e-6 * scale;  // points closer than this are one point

  reps_.clear();
  const auto eligible = [&](const Candidate& c) { return c.refined; };
  // First: among the deepest (within `tie`), the one farthest from the centroid
  // (a corner), so the choice does not flicker between equal pairs.
  {
    int best = -1;
    double best_far = -1.0;
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      const Candidate& c = candidates_[i];
      if (c.overlap < deepest - tie) continue;
      const double far = (c.point - centroid).squaredNorm();
      if (far > best_far) {
        best_far = far;
        best = static_cast<int>(i);
      }
    }
    reps_.push_back(best);
  }
  // Then: farthest from the first; largest triangle; then farthest from all chosen.
  while (static_cast<int>(reps_.size()) < limit) {
    int best = -1;
    double best_score = distinct * distinct;
    const Vec3 p0 = candidates_[reps_[0]].point;
    Vec3 axis = Vec3::Zero();
    if (reps_.size() == 2) {
      axis = candidates_[reps_[1]].point - p0;
      axis.normalize();
    }
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      const Candidate& c = candidates_[i];
      if (!eligible(c)) continue;
      double nearest = std::numeric_limits<double>::infinity();
      for (int r : reps_) nearest = std::min(nearest, (c.point - candidates_[r].point).squaredNorm());
      if (nearest <= distinct * distinct) continue;
      double score = nearest;
      if (reps_.size() == 1) score = (c.point - p0).squaredNorm();
      if (reps_.size() == 2) score = (c.point - p0).cross(axis).squaredNorm();
      if (score > best_score) {
        best_score = score;
        best = static_cast<int>(i);
      }
    }
    if (best < 0) break;
    reps_.push_back(best);
  }

  // 3. Clusters: every candidate joins its nearest representative.
  for (Candidate& c : candidates_) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t r = 0; r < reps_.size(); ++r) {
      const double d = (c.point - candidates_[reps_[r]].point).squaredNorm();
      if (d < nearest) {
        nearest = d;
        c.cluster = static_cast<int>(r);
      }
    }
  }

  // 4. One contact per cluster.
  for (std::size_t r = 0; r < reps_.size(); ++r) {
    const Candidate& rep = candidates_[reps_[r]];
    // Normal: mean over the cluster's deepest members (sphere overlap within
    // kDeepBand of its deepest): the pairs straight across the contact. A
    // voxel resting on one floor voxel also touches the next one edge-on,
    // which says nothing about the direction of this contact.
    double cluster_deepest = -std::numeric_limits<double>::infinity();
    for (const Candidate& c : candidates_) {
      if (c.cluster == static_cast<int>(r)) cluster_deepest = std::max(cluster_deepest, c.overlap);
    }
    const double deep = cluster_deepest - kDeepBand * std::abs(cluster_deepest);
    Vec3 sum = Vec3::Zero();
    for (const Candidate& c : candidates_) {
      if (c.cluster != static_cast<int>(r) || c.overlap < deep || !c.refined) continue;
      sum += c.normal;
    }
    const double sum_norm = sum.norm();
    const Vec3 normal = sum_norm > 0.0 && std::isfinite(sum_norm) ? Vec3(sum / sum_norm) : rep.normal;

    // Separation along the cluster normal: the closest aligned member (the
    // representative's own when none is aligned enough).
    double separation = std::numeric_limits<double>::infinity();
    for (const Candidate& c : candidates_) {
      if (c.cluster != static_cast<int>(r) || c.normal.dot(normal) < kAlignedCosine) continue;
      separation = std::min(separation, gap_along(c, normal));
    }
    if (!std::isfinite(separation)) separation = rep.separation;

    Contact contact;
    contact.a = body_a.id;
    contact.b = body_b.id;
    contact.index_a = index_a;
    contact.index_b = index_b;
    contact.point = rep.point;
    contact.normal = normal;
    contact.depth = std::max(0.0, rep.overlap);
    contact.separation = separation;
    contact.gap_bound = test.gapBound();
    contact.level = std::max(0, test.deepestLevel());
    contact.resolved = resolved;
    contact.priority = priority;
    contact.node_a = rep.node_a;
    contact.node_b = rep.node_b;
    out.push_back(contact);
  }
}

}  // namespace stc
