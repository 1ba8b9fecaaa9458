// Contacts from the intersecting sphere pairs of a PairTest (paper 3.5, Fig. 4).
#include "sphere_tree_collision/response.hpp"

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
// Members within this fraction of the smallest reach of the cluster's
// closest member count as in contact for its normal.
constexpr double kContactBand = 0.05;

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

  // Surface of a node towards a world direction: its voxel box within its
  // sphere, or the sphere alone without bounds.
  const auto support_a = [&](std::int32_t node, const Vec3& dir) {
    return bounds_a != nullptr ? bounds_a->support(node, rot_a.transpose() * dir) : tree_a.node(node).radius;
  };
  const auto support_b = [&](std::int32_t node, const Vec3& dir) {
    return bounds_b != nullptr ? bounds_b->support(node, rot_b.transpose() * dir) : tree_b.node(node).radius;
  };
  // Gap between the two nodes' surfaces along unit n (a -> b).
  const auto gap_along = [&](const Candidate& c, const Vec3& n) {
    return (c.cb - c.ca).dot(n) - support_a(c.node_a, n) - support_b(c.node_b, -n);
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
    c.separation = gap_along(c, c.normal);
    if (options.face_normals && (bounds_a != nullptr || bounds_b != nullptr)) {
      // A face axis of either voxel box that separates the nodes more than
      // the line of centres is the better normal (separating-axis rule):
      // face-on, the line of centres of two voxel spheres tilts by up to 45 deg.
      for (int k = 0; k < 6; ++k) {
        Vec3 axis = k < 3 ? Vec3(rot_a.col(k)) : Vec3(rot_b.col(k - 3));
        if (axis.dot(delta) < 0.0) axis = -axis;
        const double g = gap_along(c, axis);
        if (g > c.separation + 1e-12 * reach) {
          c.separation = g;
          c.normal = axis;
        }
      }
    }
    candidates_.push_back(c);
  };
  if (test.hasLastPair()) {
    for (const SpherePair& p : test.lastPairs()) add(p.a, p.b);
  } else {
    add(0, 0);
  }

  // Deepest overlap of each sphere with any partner (scratch sized to the
  // trees, reset below for the entries touched).
  deepest_of_a_.resize(tree_a.nodes().size(), -std::numeric_limits<double>::infinity());
  deepest_of_b_.resize(tree_b.nodes().size(), -std::numeric_limits<double>::infinity());
  for (const Candidate& c : candidates_) {
    double& da = deepest_of_a_[static_cast<std::size_t>(c.node_a)];
    double& db = deepest_of_b_[static_cast<std::size_t>(c.node_b)];
    da = std::max(da, c.overlap);
    db = std::max(db, c.overlap);
  }

  // 2. Representatives, spread out among the deep candidates.
  const int limit = std::clamp(options.max_contacts_per_pair, 1, 16);
  double deepest = -std::numeric_limits<double>::infinity();
  Vec3 centroid = Vec3::Zero();
  double scale = std::numeric_limits<double>::infinity();  // smallest reach: the length unit
  for (const Candidate& c : candidates_) {
    deepest = std::max(deepest, c.overlap);
    centroid += c.point;
    scale = std::min(scale, c.overlap + (c.cb - c.ca).norm());
  }
  centroid /= static_cast<double>(candidates_.size());
  const double deep_enough = deepest > 0.0 ? kRepresentativeOverlap * deepest : deepest;
  const double tie = 1e-3 * scale;      // overlaps this close count as equal
  const double distinct = 1e-6 * scale;  // points closer than this are one point

  reps_.clear();
  const auto eligible = [&](const Candidate& c) { return c.overlap >= deep_enough; };
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
    // Normal: mean over the members in closest contact that are the deepest
    // partner of their sphere on either side (a voxel resting on one floor
    // voxel also touches the next one edge-on, which says nothing about the
    // direction of this contact).
    double closest = std::numeric_limits<double>::infinity();
    for (const Candidate& c : candidates_) {
      if (c.cluster == static_cast<int>(r)) closest = std::min(closest, c.separation);
    }
    const double in_contact = closest + kContactBand * scale;
    Vec3 sum = Vec3::Zero();
    for (const Candidate& c : candidates_) {
      if (c.cluster != static_cast<int>(r) || c.overlap <= 0.0 || c.separation > in_contact) continue;
      if (c.overlap < deepest_of_a_[static_cast<std::size_t>(c.node_a)] &&
          c.overlap < deepest_of_b_[static_cast<std::size_t>(c.node_b)]) {
        continue;
      }
      sum += c.overlap * c.overlap * c.normal;
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
  for (const Candidate& c : candidates_) {
    deepest_of_a_[static_cast<std::size_t>(c.node_a)] = -std::numeric_limits<double>::infinity();
    deepest_of_b_[static_cast<std::size_t>(c.node_b)] = -std::numeric_limits<double>::infinity();
  }
}

}  // namespace stc
