// Islands and sleep: bodies that rest together stop costing anything.
//
// An island is a set of movable bodies connected by the tick's contacts
// (static bodies do not connect islands: two rocks on the same floor are two
// islands). A body rests while it stays in place (rest_test.hpp: its centre
// and its surface stay within balls of radius linear_speed * time_to_sleep / 2);
// when every body of an island has rested for `time_to_sleep` (its least rest
// timer, as Box2D v3), the island sleeps: velocities zero, pose kept exactly.
// In an island that creeping bodies keep awake, a body rested that long that
// touches no awake body short of it sleeps alone. During a tick a sleeping body is held
// as a static one (BodyState::is_static set from beginTick to endTick), so
// integration, the broad-phase box update, the sweep, the narrow phase of
// sleeping-sleeping and sleeping-static pairs and the solver all skip it with
// the tests they already make for static bodies.
//
// An island wakes whole (every body that fell asleep with it; a body that
// slept alone wakes alone): when a
// broad-phase box of a moving body (awake and not resting) or of a
// body added since the last tick overlaps one of its bodies, when one of its bodies is
// edited through World::bodies() (pose or velocity changed), removed, or
// touches (box overlap) a removed body, on World::wake and on a change of
// gravity. Flat arrays indexed like the World's bodies; nothing is allocated
// per tick once the arrays have their size.
#pragma once

#include "rest_test.hpp"
#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/phase_options.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace stc {

// An awake body's rest test and timer (a saved world's: CarriedState).
struct BodyRest {
  bool moving = true;      // not resting at the last tick
  double rest_time = 0.0;  // seconds resting
  double age = 0.0;        // seconds since its rest test's window began
  std::array<Sphere, 3> balls;  // balls[0].radius < 0: the test starts afresh
};

class Islands {
 public:
  // Mirror the World's dense arrays: a body appended (awake; its box
  // overlaps wake sleepers at the next broad phase; `reach`: its largest
  // distance from its centre of mass), a body swap-removed (index takes
  // last's place), all removed.
  void add(double reach);
  // The body just added as a saved world had it at the end of a tick: not
  // fresh, and asleep in `group` (> 0) at `pose`, or awake (0).
  void restore(std::size_t body, std::uint32_t group, const Pose& pose);
  std::uint32_t group(std::size_t body) const { return group_[body]; }
  BodyRest rest(std::size_t body) const {
    return {moving_[body] != 0, rest_time_[body], rest_test_.age(body), rest_test_.balls(body)};
  }
  void restoreRest(std::size_t body, const BodyRest& rest) {
    moving_[body] = rest.moving ? 1 : 0;
    rest_time_[body] = rest.rest_time;
    rest_test_.restore(body, rest.balls, rest.age);
  }
  // The group the next island to fall asleep takes (> 0).
  std::uint32_t nextGroup() const { return next_group_; }
  void setNextGroup(std::uint32_t group) { next_group_ = group; }
  void remove(std::size_t index, std::size_t last);
  void clear();

  bool isSleeping(std::size_t body) const { return group_[body] != kAwake; }
  // Per body, non-zero: held as static this tick because it sleeps (from
  // beginTick, less what releaseWoken releases, to endTick).
  const std::vector<std::uint8_t>& held() const { return held_; }
  std::size_t sleepingCount() const { return sleeping_; }
  // Awake and not resting at the last endTick (or edited, or new).
  bool isRestless(std::size_t body) const { return group_[body] == kAwake && moving_[body] != 0; }
  // Wakes the island of a body (nothing when it is awake), or all of them.
  void wake(std::size_t body);
  void wakeAll();

  // Tick hooks, in order. beginTick: sleepers edited since the last tick
  // wake; the others are held as static for the tick.
  void beginTick(std::vector<BodyState>& bodies, const SleepOptions& options);
  // For each broad-phase pair (dense indices), before its pair test is set
  // up: an overlap of a held body with a moving one (awake and not resting
  // at the end of the last tick, or edited) or a new one wakes
  // the held body's island. A resting awake body beside a sleeping island
  // does not wake it: it sees the island as static until it moves. True when releaseWoken() has something to release.
  bool noteOverlap(std::uint32_t a, std::uint32_t b, const std::vector<BodyState>& bodies) {
    const bool held_a = held_[a] != 0, held_b = held_[b] != 0;
    if (held_a == held_b) return false;  // both held, or both not
    const std::uint32_t other = held_a ? b : a;
    if ((!bodies[other].is_static && moving_[other] != 0) || fresh_[other] != 0) requestWake(held_a ? a : b);
    return !to_wake_.empty();
  }
  // True from beginTick while every movable body is held and none was
  // added: no pair can be tested or wake anything, the pair setup is skipped.
  bool quiet() const { return quiet_; }
  // Releases the held bodies of the islands noteOverlap woke (the pair tests
  // must then be set up again: their pairs are no longer static-static).
  void releaseWoken(std::vector<BodyState>& bodies);
  // After the response: islands from the contacts, rest timers, islands
  // asleep; every held body released (is_static false again).
  void endTick(std::vector<BodyState>& bodies, const std::vector<Contact>& contacts, double dt,
               const SleepOptions& options);

 private:
  static constexpr std::uint32_t kAwake = 0;
  void requestWake(std::size_t body);
  void applyWakes(std::vector<BodyState>* bodies);
  std::uint32_t find(std::uint32_t i);

  std::vector<std::uint32_t> group_;  // per body: island it fell asleep with, kAwake while awake
  std::vector<std::uint8_t> wake_asked_; // per body: its group is in to_wake_
  std::vector<std::uint8_t> held_;    // per body: held as static this tick
  std::vector<std::uint8_t> fresh_;   // per body: added since the last tick
  std::vector<std::uint8_t> moving_;  // per body: not resting at the last endTick, or edited
  std::vector<Pose> rest_pose_;       // per body: pose it fell asleep at (edits wake)
  std::vector<double> rest_time_;     // per body: seconds resting
  RestTest rest_test_;
  std::vector<std::uint32_t> parent_;       // union-find over the tick's contacts
  std::vector<double> island_rest_;         // per root: least rest time of its bodies
  std::vector<std::uint8_t> beside_restless_; // per body: touches an awake body not rested yet
  std::vector<std::uint32_t> island_group_; // per root: group it sleeps as (kAwake: none yet)
  std::vector<std::uint32_t> to_wake_;      // groups to wake (repeats allowed)
  std::uint32_t next_group_ = 1;
  std::size_t sleeping_ = 0;
  bool quiet_ = false;
};

}  // namespace stc
