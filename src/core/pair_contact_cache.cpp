// PairContactCache: contacts carried over while a pair barely moves (pair_contact_cache.hpp).
#include "pair_contact_cache.hpp"

#include "flat_hash_map.hpp"
#include "grow_capacity.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace stc {
namespace {

// The pose of `other` in `frame`'s frame: its origin there.
Vec3 originIn(const Pose& frame, const Pose& other) {
  return frame.orientation.conjugate() * (other.position - frame.position);
}

// Whether a unit vector (a body frame's) is one of that frame's axes: a
// face normal of its voxel boxes (ContactBuilder's face_normals).
bool alongAnAxis(const Vec3& unit) {
  constexpr double kAxis = 1.0 - 1e-9;
  return unit.cwiseAbs().maxCoeff() >= kAxis;
}

}  // namespace

PairContactCache::PairContactCache()
    : index_(std::make_unique<detail::FlatHashMap>()), next_index_(std::make_unique<detail::FlatHashMap>()) {}
PairContactCache::~PairContactCache() = default;
PairContactCache::PairContactCache(PairContactCache&&) noexcept = default;
PairContactCache& PairContactCache::operator=(PairContactCache&&) noexcept = default;

std::uint32_t PairContactCache::find(const ReuseBody& a, const ReuseBody& b, double dt) const {
  if (entries_.empty()) return kNone;
  const std::uint32_t index = index_->find(entityPairKey(a.id, b.id));
  if (index == detail::FlatHashMap::kMissing) return kNone;
  const Entry& e = entries_[index];
  const Pose& pa = *a.pose;
  const Pose& pb = *b.pose;
  // First, without a rotation: the centres' distance changed by at most what
  // either origin moved in the other's frame (rotations keep lengths), so a
  // change beyond the tolerance leaves both measures below beyond it too. A
  // pair that moves (most, while a pile forms) costs a norm; the margin keeps
  // rounding from turning away a pair the measures below would take.
  const double distance_change = std::abs((pb.position - pa.position).norm() - e.b_in_a.norm());
  if (distance_change > e.tolerance * (1.0 + 1e-9) + 1e-12) return kNone;
  // How far the relative pose moved since the entry was made: a point of B at
  // distance r from its origin moved, in A's frame, by at most the shift of
  // B's origin there plus the chord of the relative turn at r (2 r sin(angle/2),
  // sin(angle/2) being the turn's quaternion's vector part). The same seen
  // from B; either bound holds, so the smaller is taken (a big static plate
  // barely turns against the small body on it).
  const Quat turn = e.a_to_b.conjugate() * (pa.orientation.conjugate() * pb.orientation);
  const double chord = 2.0 * turn.vec().norm();
  // Their speed now the same way: a point of B at distance r from its origin
  // moves in A's frame at most at |v_b - v_a - w_a x d| + |w_b - w_a| r.
  const Vec3 d = pb.position - pa.position;
  const double spin = (b.angular_velocity - a.angular_velocity).norm();
  const double speed_in_a = (b.linear_velocity - a.linear_velocity - a.angular_velocity.cross(d)).norm() +
                            spin * b.radius;
  const double speed_in_b = (a.linear_velocity - b.linear_velocity + b.angular_velocity.cross(d)).norm() +
                            spin * a.radius;
  const double ahead = kMotionTicks * dt;
  const double seen_from_a = (originIn(pa, pb) - e.b_in_a).norm() + chord * b.radius + ahead * speed_in_a;
  const Vec3 a_in_b = -(e.a_to_b.conjugate() * e.b_in_a);  // A's origin in B's frame then
  const double seen_from_b = (originIn(pb, pa) - a_in_b).norm() + chord * a.radius + ahead * speed_in_b;
  // Not `>`: a NaN pose never reuses.
  return std::min(seen_from_a, seen_from_b) <= e.tolerance ? index : kNone;
}

void PairContactCache::place(std::uint32_t index, const Contact& base, const Pose& pose_a, const Pose& pose_b,
                             std::vector<Contact>& out) const {
  const Entry& e = entries_[index];
  for (std::uint32_t k = e.first; k < e.first + e.count; ++k) {
    const Point& p = points_[k];
    Contact c = base;
    const Vec3 on_a = pose_a.apply(p.on_a);
    const Vec3 on_b = pose_b.apply(p.on_b);
    c.normal = ((p.normal_of_b ? pose_b.orientation : pose_a.orientation) * p.normal).normalized();
    c.separation = (on_b - on_a).dot(c.normal);
    c.point = 0.5 * (on_a + on_b);
    c.depth = std::max(p.depth - (c.separation - p.separation), 0.0);
    c.gap_bound = c.sphere_bound = p.sphere_bound;
    c.level = p.level;
    c.resolved = p.resolved;
    if (!p.resolved) c.separation = std::max(c.separation, 0.0);
    c.node_a = p.node_a;
    c.node_b = p.node_b;
    out.push_back(c);
  }
}

void PairContactCache::record(const PairTest& test, const ReuseBody& a, const ReuseBody& b, double tolerance,
                              const Contact* first, const Contact* end, Pending& pending) {
  assert(test.status() == PairStatus::Unresolved || (test.status() == PairStatus::Colliding && test.hasLastPair()));
  const Pose& pa = *a.pose;
  const Pose& pb = *b.pose;
  Entry e;
  e.key = entityPairKey(a.id, b.id);
  e.b_in_a = originIn(pa, pb);
  e.a_to_b = pa.orientation.conjugate() * pb.orientation;
  e.tolerance = tolerance;
  if (test.hasLastPair()) e.leaf = test.lastPair();
  e.level = test.deepestLevel();
  e.first = static_cast<std::uint32_t>(pending.points.size());
  e.count = static_cast<std::uint32_t>(end - first);
  const Quat to_a = pa.orientation.conjugate();
  const Quat to_b = pb.orientation.conjugate();
  for (const Contact* c = first; c != end; ++c) {
    // The contact point is halfway between the two surfaces along the normal.
    const Vec3 half = 0.5 * c->separation * c->normal;
    Point p;
    p.on_a = to_a * (c->point - half - pa.position);
    p.on_b = to_b * (c->point + half - pb.position);
    const Vec3 normal_in_a = to_a * c->normal;
    const Vec3 normal_in_b = to_b * c->normal;
    p.normal_of_b = !alongAnAxis(normal_in_a) && alongAnAxis(normal_in_b);
    p.normal = p.normal_of_b ? normal_in_b : normal_in_a;
    p.depth = c->depth;
    p.separation = c->separation;
    p.sphere_bound = c->sphere_bound;
    p.node_a = c->node_a;
    p.node_b = c->node_b;
    p.level = c->level;
    p.resolved = c->resolved;
    pending.points.push_back(p);
  }
  pending.entries.push_back(e);
}

void PairContactCache::carry(std::uint32_t index, Pending& pending) const {
  Entry e = entries_[index];
  const std::uint32_t first = e.first;
  e.first = static_cast<std::uint32_t>(pending.points.size());
  pending.points.insert(pending.points.end(), points_.begin() + first, points_.begin() + first + e.count);
  pending.entries.push_back(e);
}

void PairContactCache::commit(const Pending* const* pending, std::size_t count) {
  next_entries_.clear();
  next_points_.clear();
  next_index_->clear();
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint32_t offset = static_cast<std::uint32_t>(next_points_.size());
    for (Entry e : pending[k]->entries) {
      e.first += offset;
      next_index_->set(e.key, static_cast<std::uint32_t>(next_entries_.size()));
      next_entries_.push_back(e);
    }
    next_points_.insert(next_points_.end(), pending[k]->points.begin(), pending[k]->points.end());
  }
  entries_.swap(next_entries_);
  points_.swap(next_points_);
  index_.swap(next_index_);
}

void PairContactCache::Pending::reserve(std::size_t entry_count, std::size_t point_count) {
  growCapacity(entries, entry_count);
  growCapacity(points, point_count);
}

void PairContactCache::reserve(std::size_t entries, std::size_t points) {
  for (std::vector<Entry>* v : {&entries_, &next_entries_}) growCapacity(*v, entries);
  for (std::vector<Point>* v : {&points_, &next_points_}) growCapacity(*v, points);
  index_->reserve(entries);
  next_index_->reserve(entries);
}

void PairContactCache::restore(const std::vector<Entry>& entries, const std::vector<Point>& points) {
  entries_ = entries;
  points_ = points;
  index_->clear();
  for (std::uint32_t i = 0; i < entries_.size(); ++i) index_->set(entries_[i].key, i);
}

void PairContactCache::clear() {
  entries_.clear();
  points_.clear();
  index_->clear();
}

}  // namespace stc
