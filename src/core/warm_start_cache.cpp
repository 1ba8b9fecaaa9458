// The solver's warm start between ticks: the last solve's store, the held
// store of sleeping pairs, and how a solve's manifolds become the next store.
#include "warm_start_cache.hpp"

#include "grow_capacity.hpp"

#include <algorithm>
#include <cassert>
#include <utility>

namespace stc {

void WarmStartCache::restore(std::vector<Manifold> solved, std::vector<Point> solved_points,
                             std::vector<Manifold> held, std::vector<Point> held_points) {
  std::sort(solved.begin(), solved.end(), byPair);
  std::sort(held.begin(), held.end(), byPair);
  manifolds_ = std::move(solved);
  points_ = std::move(solved_points);
  held_manifolds_ = std::move(held);
  held_points_ = std::move(held_points);
}

void WarmStartCache::clear() {
  points_.clear();
  manifolds_.clear();
  held_points_.clear();
  held_manifolds_.clear();
}

const WarmStartCache::Manifold* WarmStartCache::find(std::uint64_t pair, const Point*& points) const {
  const auto byKey = [](const Manifold& x, std::uint64_t k) { return x.pair < k; };
  const auto solved = std::lower_bound(manifolds_.begin(), manifolds_.end(), pair, byKey);
  if (solved != manifolds_.end() && solved->pair == pair) {
    points = points_.data() + solved->first;
    return &*solved;
  }
  const auto held = std::lower_bound(held_manifolds_.begin(), held_manifolds_.end(), pair, byKey);
  if (held != held_manifolds_.end() && held->pair == pair) {
    points = held_points_.data() + held->first;
    return &*held;
  }
  return nullptr;
}

void WarmStartCache::reserve(std::size_t rows) {
  for (std::vector<Manifold>* v : {&manifolds_, &next_manifolds_}) growCapacity(*v, rows);
  for (std::vector<Point>* v : {&points_, &next_points_}) growCapacity(*v, rows);
}

void WarmStartCache::beginNext(std::size_t points, std::size_t manifolds) {
  next_points_.resize(points);
  next_manifolds_.resize(manifolds);
}

void WarmStartCache::keepPoint(std::size_t at, const Contact& c, const Pose& pose_a, double normal,
                               const Vec3& friction) {
  Point& point = next_points_[at];
  point.node_a = c.node_a;
  point.node_b = c.node_b;
  point.local_a = pose_a.orientation.conjugate() * (c.point - pose_a.position);
  point.normal = normal;
  point.friction = friction;
}

void WarmStartCache::commitNext(const std::vector<std::uint8_t>& out_of_solve) {
  std::sort(next_manifolds_.begin(), next_manifolds_.end(), byPair);
  keepHeldManifolds(out_of_solve);
}

void WarmStartCache::commitNone(const std::vector<std::uint8_t>& out_of_solve) {
  next_points_.clear();
  next_manifolds_.clear();
  keepHeldManifolds(out_of_solve);
}

// Tested first, so an awake world pays two look-ups a manifold. A pair
// solved this tick has a movable body, so it never qualifies: the held store
// and the solved store never share a pair.
bool WarmStartCache::stillHeld(const Manifold& m, const std::vector<std::uint8_t>& out_of_solve) const {
  const std::uint32_t ia = m.index_a, ib = m.index_b;
  const std::vector<std::uint8_t>& held = *held_bodies_;
  return ia < out_of_solve.size() && ib < out_of_solve.size() && (held[ia] != 0 || held[ib] != 0) &&
         out_of_solve[ia] != 0 && out_of_solve[ib] != 0 && (*ids_)[ia] == static_cast<EntityId>(m.pair >> 32) &&
         (*ids_)[ib] == static_cast<EntityId>(m.pair & 0xffffffffu);
}

void WarmStartCache::keepHeldManifolds(const std::vector<std::uint8_t>& out_of_solve) {
  if (ids_ == nullptr || held_bodies_ == nullptr) {
    held_manifolds_.clear();
    held_points_.clear();
  } else {
    dropWoken(out_of_solve);
    holdFallenAsleep(out_of_solve);
    assert(std::is_sorted(held_manifolds_.begin(), held_manifolds_.end(), byPair));
  }
  points_.swap(next_points_);
  manifolds_.swap(next_manifolds_);
}

// What no longer sleeps (woken, despawned) leaves the held store; the rest
// stays where it is unless something left.
void WarmStartCache::dropWoken(const std::vector<std::uint8_t>& out_of_solve) {
  const std::size_t stored = held_manifolds_.size();
  std::size_t kept = 0;
  while (kept < stored && stillHeld(held_manifolds_[kept], out_of_solve)) ++kept;
  if (kept == stored) return;
  held_points_scratch_.clear();
  std::size_t out = 0;
  for (std::size_t k = 0; k < stored; ++k) {
    Manifold m = held_manifolds_[k];
    if (!stillHeld(m, out_of_solve)) continue;
    const std::uint32_t first = static_cast<std::uint32_t>(held_points_scratch_.size());
    held_points_scratch_.insert(held_points_scratch_.end(), held_points_.begin() + m.first,
                                held_points_.begin() + m.first + m.count);
    m.first = first;
    held_manifolds_[out++] = m;
  }
  held_manifolds_.resize(out);
  held_points_.swap(held_points_scratch_);
}

// Last solve's manifolds whose pairs now sleep join the held store (both
// lists are sorted by pair: one merge).
void WarmStartCache::holdFallenAsleep(const std::vector<std::uint8_t>& out_of_solve) {
  const std::size_t before = held_manifolds_.size();
  for (const Manifold& old : manifolds_) {
    if (!stillHeld(old, out_of_solve)) continue;
    Manifold m = old;
    m.first = static_cast<std::uint32_t>(held_points_.size());
    held_points_.insert(held_points_.end(), points_.begin() + old.first, points_.begin() + old.first + old.count);
    held_manifolds_.push_back(m);
  }
  if (before == 0 || held_manifolds_.size() == before) return;
  held_merge_.resize(held_manifolds_.size());
  std::merge(held_manifolds_.begin(), held_manifolds_.begin() + static_cast<std::ptrdiff_t>(before),
             held_manifolds_.begin() + static_cast<std::ptrdiff_t>(before), held_manifolds_.end(),
             held_merge_.begin(), byPair);
  held_manifolds_.swap(held_merge_);
}

}  // namespace stc
