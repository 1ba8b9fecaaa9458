// Islands and sleep (islands.hpp): union-find over the tick's contacts, rest
// timers per body, whole islands put to sleep and woken.
#include "islands.hpp"

#include "union_find.hpp"

#include "sphere_tree_collision/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace stc {
namespace {

void requireNonNegative(double value, const char* field) {
  if (!(std::isfinite(value) && value >= 0.0)) throw InputError(field, "must be finite and >= 0");
}

bool samePose(const Pose& a, const Pose& b) {
  return a.position == b.position && a.orientation.coeffs() == b.orientation.coeffs();
}

}  // namespace

void validateSleepOptions(const SleepOptions& options) {
  requireNonNegative(options.linear_speed, "sleeping.linear_speed");
  requireNonNegative(options.time_to_sleep, "sleeping.time_to_sleep");
}

void Islands::add(double reach) {
  rest_test_.add(reach);
  group_.push_back(kAwake);
  // A body asks for its group at most once between wakes: room for one group per body
  // keeps requestWake from allocating mid-tick (lone sleepers make one group per body).
  if (to_wake_.capacity() < group_.size()) to_wake_.reserve(2 * group_.size());
  wake_asked_.push_back(0);
  held_.push_back(0);
  fresh_.push_back(1);
  moving_.push_back(1);
  rest_pose_.emplace_back();
  rest_time_.push_back(0.0);
}

void Islands::restore(std::size_t body, std::uint32_t group, const Pose& pose) {
  fresh_[body] = 0;
  if (group == kAwake) return;
  group_[body] = group;
  moving_[body] = 0;
  rest_pose_[body] = pose;
  ++sleeping_;
  if (group >= next_group_) next_group_ = group == std::numeric_limits<std::uint32_t>::max() ? 1 : group + 1;
}

void Islands::remove(std::size_t index, std::size_t last) {
  if (group_[index] != kAwake) {
    // The removed body's island loses a support: the rest of it wakes.
    requestWake(index);
    applyWakes(nullptr);
  }
  rest_test_.remove(index, last);
  group_[index] = group_[last];
  wake_asked_[index] = wake_asked_[last];
  held_[index] = held_[last];
  fresh_[index] = fresh_[last];
  moving_[index] = moving_[last];
  rest_pose_[index] = rest_pose_[last];
  rest_time_[index] = rest_time_[last];
  group_.pop_back();
  wake_asked_.pop_back();
  held_.pop_back();
  fresh_.pop_back();
  moving_.pop_back();
  rest_pose_.pop_back();
  rest_time_.pop_back();
}

void Islands::clear() {
  group_.clear();
  wake_asked_.clear();
  held_.clear();
  fresh_.clear();
  moving_.clear();
  rest_pose_.clear();
  rest_time_.clear();
  rest_test_.clear();
  to_wake_.clear();
  sleeping_ = 0;
}

// Constant time: a body asks once (a pile's restless rocks touch many sleepers,
// each overlap asks), and a group asked for by several bodies is listed again.
void Islands::requestWake(std::size_t body) {
  if (group_[body] == kAwake || wake_asked_[body] != 0) return;
  wake_asked_[body] = 1;
  to_wake_.push_back(group_[body]);
}

// One pass over the bodies wakes every requested group (sorted first: with
// lone sleepers many groups can wake at once, and each body looks its group up).
void Islands::applyWakes(std::vector<BodyState>* bodies) {
  if (to_wake_.empty()) return;
  std::sort(to_wake_.begin(), to_wake_.end());
  for (std::size_t i = 0; i < group_.size(); ++i) {
    if (group_[i] == kAwake) continue;
    if (!std::binary_search(to_wake_.begin(), to_wake_.end(), group_[i])) continue;
    wake_asked_[i] = 0;  // only sleepers ask, and each asking body's group is listed
    group_[i] = kAwake;
    rest_time_[i] = 0.0;
    rest_test_.restart(i);
    --sleeping_;
    if (held_[i] != 0 && bodies != nullptr) {
      held_[i] = 0;
      (*bodies)[i].is_static = false;
    }
  }
  to_wake_.clear();
}

void Islands::wake(std::size_t body) {
  requestWake(body);
  applyWakes(nullptr);
}

void Islands::wakeAll() {
  std::fill(group_.begin(), group_.end(), kAwake);
  std::fill(wake_asked_.begin(), wake_asked_.end(), 0);
  std::fill(rest_time_.begin(), rest_time_.end(), 0.0);
  for (std::size_t i = 0; i < group_.size(); ++i) rest_test_.restart(i);
  to_wake_.clear();
  sleeping_ = 0;
}

void Islands::beginTick(std::vector<BodyState>& bodies, const SleepOptions& options) {
  quiet_ = false;
  if (!options.enabled || sleeping_ == 0) return;
  for (std::size_t i = 0; i < group_.size(); ++i) {
    if (group_[i] == kAwake) continue;
    const BodyState& body = bodies[i];
    const bool edited = !samePose(body.pose, rest_pose_[i]) || !body.linear_velocity.isZero(0.0) ||
                        !body.angular_velocity.isZero(0.0);
    if (!edited) continue;
    requestWake(i);
    moving_[i] = 1;  // its overlaps wake what it touches
  }
  applyWakes(nullptr);
  quiet_ = true;
  for (std::size_t i = 0; i < group_.size(); ++i) {
    quiet_ = quiet_ && fresh_[i] == 0;
    if (bodies[i].is_static) continue;
    if (group_[i] == kAwake) {
      quiet_ = false;
      continue;
    }
    held_[i] = 1;
    bodies[i].is_static = true;
  }
}

void Islands::releaseWoken(std::vector<BodyState>& bodies) { applyWakes(&bodies); }

std::uint32_t Islands::find(std::uint32_t i) { return findRoot(parent_, i); }

void Islands::endTick(std::vector<BodyState>& bodies, const std::vector<Contact>& contacts, double dt,
                      const SleepOptions& options) {
  const std::size_t n = bodies.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (held_[i] == 0) continue;
    held_[i] = 0;
    bodies[i].is_static = false;
  }
  std::fill(fresh_.begin(), fresh_.end(), 0);
  if (!options.enabled) return;

  const auto movable = [&](std::size_t i) { return !bodies[i].is_static && group_[i] == kAwake; };

  // Rest timers. A point moving steadily at linear_speed goes a ball's
  // diameter in time_to_sleep (a tick at least).
  const double max_radius = 0.5 * options.linear_speed * std::max(options.time_to_sleep, dt);
  for (std::size_t i = 0; i < n; ++i) {
    if (!movable(i)) continue;
    const bool resting = rest_test_.update(i, bodies[i].pose, dt, options.time_to_sleep, max_radius);
    rest_time_[i] = resting ? rest_time_[i] + dt : 0.0;
    moving_[i] = resting ? 0 : 1;
  }

  // Islands of the awake movable bodies: a contact joins two of them; each
  // island's least rest time (Box2D v3).
  parent_.resize(n);
  std::iota(parent_.begin(), parent_.end(), 0u);
  for (const Contact& c : contacts) {
    if (!movable(c.index_a) || !movable(c.index_b)) continue;
    uniteRoots(parent_, c.index_a, c.index_b);
  }
  island_rest_.assign(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    if (!movable(i)) continue;
    double& least = island_rest_[find(static_cast<std::uint32_t>(i))];
    least = std::min(least, rest_time_[i]);
  }

  // An island whose bodies all rested time_to_sleep sleeps whole, as one
  // group. In a big island that a few creeping rocks keep awake (measured:
  // bench_settle's restless line, docs/sleeping.md) a body that rested that
  // long and touches no awake body short of it sleeps alone, its own group:
  // the rested bodies touching the others stay awake around them, seeing the
  // sleepers as static, and when one of them moves its box wakes the sleepers
  // it reaches (noteOverlap), as any moving body's does.
  const auto rested = [&](std::size_t i) { return rest_time_[i] >= options.time_to_sleep; };
  beside_restless_.assign(n, 0);
  for (const Contact& c : contacts) {
    if (!movable(c.index_a) || !movable(c.index_b)) continue;
    const bool ra = rested(c.index_a), rb = rested(c.index_b);
    if (ra != rb) beside_restless_[ra ? c.index_a : c.index_b] = 1;
  }
  const auto newGroup = [&] {
    const std::uint32_t group = next_group_;
    next_group_ = next_group_ == std::numeric_limits<std::uint32_t>::max() ? 1 : next_group_ + 1;
    return group;
  };
  island_group_.assign(n, kAwake);
  for (std::size_t i = 0; i < n; ++i) {
    if (!movable(i)) continue;
    const std::uint32_t root = find(static_cast<std::uint32_t>(i));
    const bool whole = island_rest_[root] >= options.time_to_sleep;
    if (!whole && !(rested(i) && beside_restless_[i] == 0)) continue;
    if (whole && island_group_[root] == kAwake) island_group_[root] = newGroup();
    group_[i] = whole ? island_group_[root] : newGroup();
    moving_[i] = 0;
    rest_pose_[i] = bodies[i].pose;
    bodies[i].linear_velocity.setZero();
    bodies[i].angular_velocity.setZero();
    ++sleeping_;
  }
}

}  // namespace stc
