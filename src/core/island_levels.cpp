// Island levels (island_levels.hpp): awake islands ranked by the viewer's
// priority and their wait, the ones beyond the allowance held still.
#include "island_levels.hpp"

#include "union_find.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace stc {

const char* responseLevelName(ResponseLevel level) {
  switch (level) {
    case ResponseLevel::Full: return "full";
    case ResponseLevel::Held: return "held";
    case ResponseLevel::Asleep: return "asleep";
    case ResponseLevel::Static: return "static";
  }
  return "full";
}

void IslandLevels::add() {
  held_.push_back(0);
  waited_.push_back(0);
}

void IslandLevels::remove(std::size_t index, std::size_t last) {
  held_[index] = held_[last];
  waited_[index] = waited_[last];
  held_.pop_back();
  waited_.pop_back();
}

void IslandLevels::clear() {
  held_.clear();
  waited_.clear();
  held_count_ = 0;
}

std::uint32_t IslandLevels::find(std::uint32_t i) { return findRoot(parent_, i); }

void IslandLevels::unite(std::uint32_t a, std::uint32_t b) { uniteRoots(parent_, a, b); }

Aabb IslandLevels::heldBox(const BodyState& body, double reach, double dt) {
  const Vec3 start = body.pose.position;
  const Vec3 end = start + body.linear_velocity * dt;  // as integratePosition moves it
  Aabb box;
  box.min = start.cwiseMin(end) - Vec3::Constant(reach);
  box.max = start.cwiseMax(end) + Vec3::Constant(reach);
  return box;
}

void IslandLevels::choose(const Inputs& in, IslandLevelReport& report) {
  std::vector<BodyState>& bodies = *in.bodies;
  const std::size_t n = bodies.size();
  assert(held_.size() == n && waited_.size() == n);
  report = IslandLevelReport{};
  report.used = true;
  report.allowance = in.allowance;
  held_count_ = 0;
  // Scratch by body index: resized, so allocated only when the world grows.
  parent_.resize(n);
  candidate_.resize(n);
  joined_.resize(n);
  reached_.resize(n);
  cost_.resize(n);
  priority_.resize(n);
  island_wait_.resize(n);
  island_bodies_.resize(n);
  root_held_.resize(n);
  ranked_.reserve(n);  // at most an island a body: grown as the islands passed their high, a tick allocated
  for (std::size_t i = 0; i < n; ++i) {
    parent_[i] = static_cast<std::uint32_t>(i);
    candidate_[i] = bodies[i].is_static ? 0 : 1;  // sleepers are held static already
    held_[i] = 0;
    joined_[i] = 0;
    cost_[i] = 0.0;
    priority_[i] = 0.0;
    island_wait_[i] = 0;
    island_bodies_[i] = 0;
    root_held_[i] = 0;
  }
  // Islands of last tick's contacts, and what each will cost: its contacts.
  for (const Contact& c : *in.contacts) {
    assert(c.index_a < n && c.index_b < n);
    if (candidate_[c.index_a] != 0 && candidate_[c.index_b] != 0) unite(c.index_a, c.index_b);
  }
  for (const Contact& c : *in.contacts) {
    const std::uint32_t mover = candidate_[c.index_a] != 0 ? c.index_a : c.index_b;
    if (candidate_[mover] != 0) cost_[find(mover)] += 1.0;
  }
  const bool gaze = in.perception != nullptr && in.perception->hasFixation();
  for (std::size_t i = 0; i < n; ++i) {
    if (candidate_[i] == 0) continue;
    const std::uint32_t root = find(static_cast<std::uint32_t>(i));
    cost_[root] += 1.0;  // the body itself: integration, its box
    ++island_bodies_[root];
    if (gaze) priority_[root] = std::max(priority_[root], in.perception->gazeWeight(bodies[i].pose.position).weight);
    island_wait_[root] = std::max(island_wait_[root], waited_[i]);
  }
  ranked_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (candidate_[i] == 0 || parent_[i] != i) continue;
    Ranked r;
    r.priority = priority_[i];
    r.waited = island_wait_[i];
    r.key = r.priority + kAgingPerTick * r.waited;
    r.cost = cost_[i];
    r.root = static_cast<std::uint32_t>(i);
    r.bodies = island_bodies_[i];
    ranked_.push_back(r);
    if (r.bodies > report.largest_island) {
      report.largest_island = r.bodies;
      report.largest_cost = r.cost;
    }
  }
  std::sort(ranked_.begin(), ranked_.end(), [](const Ranked& x, const Ranked& y) {
    return x.key != y.key ? x.key > y.key : x.root < y.root;
  });
  // In order: the first runs (the queue moves), an island that waited long
  // enough runs, and any other that still fits.
  double used = 0.0;
  bool first = true;
  for (const Ranked& r : ranked_) {
    const bool runs = first || r.waited >= kMostTicksHeld || used + r.cost <= in.allowance;
    first = false;
    if (runs) {
      used += r.cost;
      ++report.islands_full;
      continue;
    }
    root_held_[r.root] = 1;
    ++report.islands_held;
    report.held_priority += r.priority;
  }
  report.full_cost = used;
  if (report.islands_held == 0) {
    report.bodies_full = static_cast<std::size_t>(std::count(candidate_.begin(), candidate_.end(), 1));
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (candidate_[i] == 0) continue;
    if (root_held_[find(static_cast<std::uint32_t>(i))] == 0) {
      ++report.bodies_full;
      continue;
    }
    held_[i] = 1;
    bodies[i].is_static = true;
    ++held_count_;
    ++report.bodies_held;
  }
}

void IslandLevels::releaseReached(std::vector<BodyState>& bodies, IslandLevelReport& report) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (held_[i] == 0 || reached_[find(static_cast<std::uint32_t>(i))] == 0) continue;
    held_[i] = 0;
    bodies[i].is_static = false;
    joined_[i] = 1;
    --held_count_;
    ++report.bodies_full;
    --report.bodies_held;
  }
  for (const Ranked& r : ranked_) {
    if (root_held_[r.root] == 0 || joined_[r.root] == 0) continue;
    root_held_[r.root] = 0;
    ++report.islands_joined;
    ++report.islands_full;
    --report.islands_held;
    report.held_priority -= r.priority;
  }
}

void IslandLevels::unused() {
  if (!any_marked_) return;
  std::fill(held_.begin(), held_.end(), 0);
  std::fill(waited_.begin(), waited_.end(), 0);
  any_marked_ = false;
}

void IslandLevels::release(std::vector<BodyState>& bodies, IslandLevelReport& report) {
  const std::size_t n = bodies.size();
  assert(held_.size() == n && waited_.size() == n);
  for (std::size_t i = 0; i < n; ++i) {
    if (held_[i] == 0) {
      waited_[i] = 0;
      continue;
    }
    bodies[i].is_static = false;
    ++waited_[i];
    any_marked_ = true;
    report.most_ticks_held = std::max(report.most_ticks_held, static_cast<int>(waited_[i]));
  }
  held_count_ = 0;
}

}  // namespace stc
