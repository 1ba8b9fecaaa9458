// Island levels: a refineable response (paper 3.5 and 4, "a lower level of
// collision response to fall back on"; issue 49, item 4).
//
// Under a limited response (a tick budget, or Budget::response_contacts) the
// awake islands are ranked at the tick's start and given one of two levels:
//   Full  integrated, tested and solved as every body is without a budget;
//   Held  still for the tick: not integrated, no contacts built, not solved;
//         pose, velocity and angular velocity kept exactly (so its momentum),
//         it waits for its turn.
// An island here is a set of awake movable bodies joined by last tick's
// contacts (as Islands' union-find, islands.hpp). Its cost is last tick's
// contacts touching it plus one per body; its priority is the viewer's: the
// largest gaze weight exp(-e / 100) of its bodies' centres (e: eccentricity
// in pixels from the fixation, perception.hpp; 0 behind the camera or without
// a fixation), plus kAgingPerTick for each tick it has waited. The first island
// in that order always runs, then each that still fits the allowance, in
// order; an island held kMostTicksHeld ticks in a row runs whatever it costs.
// So none starves: every island is stepped at least once in kMostTicksHeld + 1
// ticks.
//
// A held body does not move this tick, so it must not be hit as a wall: its
// broad-phase box covers where it would have gone (its bounding cube over
// its path, heldBox), and a broad-phase pair of a held body with a body that
// moves this tick (stepped, woken, new) whose paths come near (the World's
// test: their bounding spheres over the tick's path) joins the held body's
// island to the tick: it is integrated after the broad phase (its box
// already covered that) and solved with the others. Held bodies whose paths
// come near join each other, so a join reaches everything a released body
// could touch.
// During the tick a held body is static to the phases (BodyState::is_static,
// as sleepers, islands.hpp); the World releases it after Islands::endTick.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/tick_report.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace stc {

class IslandLevels {
 public:
  static constexpr double kAgingPerTick = 0.1;  // priority an island gains per tick waited
  static constexpr int kMostTicksHeld = 30;     // then it runs whatever it costs (0.5 s at 60 Hz)

  // Mirror the World's dense arrays (Islands::add/remove/clear).
  void add();
  void remove(std::size_t index, std::size_t last);
  void clear();

  // What choose() reads: the bodies (sleepers held static already), last
  // tick's contacts (dense indices), the viewer (nullptr or no fixation:
  // every priority 0) and the allowance in cost units.
  struct Inputs {
    std::vector<BodyState>* bodies = nullptr;
    const std::vector<Contact>* contacts = nullptr;
    const Perception* perception = nullptr;
    double allowance = 0.0;
  };
  // Ranks the awake islands and holds the ones that do not fit: is_static
  // set on their bodies until release(). Fills report.
  void choose(const Inputs& in, IslandLevelReport& report);
  // A held body's broad-phase box: its bounding cube (`reach`: the shape's
  // bounding radius) over its path of the tick, pose to pose + v dt.
  static Aabb heldBox(const BodyState& body, double reach, double dt);
  // Held now (during the tick), or held by the last tick (between ticks).
  bool isHeld(std::size_t body) const { return body < held_.size() && held_[body] != 0; }
  // A tick without levels: every body Full, no waits (O(1) when already so).
  void unused();
  bool anyHeld() const { return held_count_ != 0; }
  // After the broad phase: of the broad-phase pairs pair_at(0..count) (dense
  // indices) those that `near(a, b)` says can touch this tick join to the
  // tick each held island a moving body (not static, so not held nor asleep)
  // reaches, directly or through other held bodies. Their bodies are
  // released (is_static false) and flagged in joined() for the late
  // integration. True when something was released.
  template <typename PairAt, typename Near>
  bool join(std::vector<BodyState>& bodies, std::size_t count, const PairAt& pair_at, const Near& near,
            IslandLevelReport& report);
  const std::vector<std::uint8_t>& joined() const { return joined_; }
  // After Islands::endTick: held bodies movable again; their wait grows,
  // every stepped body's is 0.
  void release(std::vector<BodyState>& bodies, IslandLevelReport& report);

 private:
  std::uint32_t find(std::uint32_t i);
  void unite(std::uint32_t a, std::uint32_t b);
  void releaseReached(std::vector<BodyState>& bodies, IslandLevelReport& report);

  struct Ranked {
    double key = 0.0;        // priority + aging
    double priority = 0.0;   // gaze priority alone
    double cost = 0.0;
    std::uint32_t bodies = 0;
    std::uint32_t root = 0;  // the island's union-find root (a body index)
    int waited = 0;
  };
  std::vector<std::uint32_t> parent_;     // union-find over bodies
  std::vector<std::uint8_t> candidate_;   // awake movable at choose
  std::vector<std::uint8_t> held_;        // held this tick (kept after release until the next choose)
  std::vector<std::uint8_t> joined_;      // released by join this tick
  std::vector<std::uint8_t> reached_;     // per root: a moving body reaches it
  std::vector<std::int32_t> waited_;      // per body: ticks held in a row
  std::vector<double> cost_, priority_;   // per root
  std::vector<std::int32_t> island_wait_; // per root
  std::vector<std::uint32_t> island_bodies_; // per root
  std::vector<Ranked> ranked_;
  std::vector<std::uint8_t> root_held_;   // per root of choose: its island is held
  std::size_t held_count_ = 0;
  bool any_marked_ = false;  // held_ or waited_ has a non-zero entry
};

template <typename PairAt, typename Near>
bool IslandLevels::join(std::vector<BodyState>& bodies, std::size_t count, const PairAt& pair_at, const Near& near,
                        IslandLevelReport& report) {
  if (held_count_ == 0) return false;
  // Held bodies keep their island's root from choose (parent_); overlapping
  // held bodies join; a held group a moving body touches is reached.
  for (std::size_t k = 0; k < count; ++k) {
    const auto [a, b] = pair_at(k);
    if (held_[a] != 0 && held_[b] != 0 && near(a, b)) unite(a, b);
  }
  std::fill(reached_.begin(), reached_.end(), 0);
  bool any = false;
  for (std::size_t k = 0; k < count; ++k) {
    const auto [a, b] = pair_at(k);
    if ((held_[a] != 0) == (held_[b] != 0)) continue;
    const std::uint32_t h = held_[a] != 0 ? a : b, other = held_[a] != 0 ? b : a;
    if (bodies[other].is_static) continue;  // static or asleep: does not move this tick
    if (!near(h, other)) continue;
    reached_[find(h)] = 1;
    any = true;
  }
  if (any) releaseReached(bodies, report);
  return any;
}

}  // namespace stc
