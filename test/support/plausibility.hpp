// Is a run of a built-in scene physically plausible (issue 49, item 4)? The
// figures a physicist would check, taken tick by tick beside World::step and
// summed up at the end; test_budget_plausibility asserts them and
// bench_steady_frame_rate prints them for a budgeted run and the unbudgeted
// one beside it. Untimed: read between ticks.
#pragma once

#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include <string>
#include <unordered_map>
#include <vector>

namespace stc::truth {

struct Plausibility {
  std::size_t movers = 0;      // the scene's movers
  std::size_t non_finite = 0;  // movers with a non-finite pose or velocity at the end
  std::size_t outside = 0;     // movers out of the scene's bounds at the end, or removed
  // Stored against real speed, per mover over windows of kPlausibilityWindow
  // ticks: the mean |v| it was stored with at the start of each tick against
  // the mean |dx| / dt it then moved (a window, not a tick: a body swept back
  // to its first contact moves part of one tick, and a pile's position
  // correction moves a resting body a little; neither is a stored speed
  // without motion). A window's excess is |stored - real| - (10 % real +
  // 0.05 m/s); it is off when that is > 0. Ticks a mover was held still by
  // its island's level (World::responseLevel) are left out: its time stood,
  // and its windows are of kPlausibilityWindow ticks it was stepped.
  double worst_window_excess = -1.0;
  std::size_t windows = 0, bad_windows = 0;
  double max_speed = 0.0;   // m/s, the fastest mover at any tick
  double fall_speed = 0.0;  // m/s: the fastest start plus a fall from the highest mover to the bounds' floor
  std::size_t too_fast = 0; // movers faster than fall_speed at some tick
  // How deep the movers' voxels reach into the static plates at the end
  // (deepestInStatic), in each mover's own voxels: the deepest, the 99th
  // percentile over the movers, and how many reach more than one voxel deep.
  double max_sink_voxels = 0.0, sink_p99_voxels = 0.0;
  std::size_t sunk = 0;
  double max_sink = 0.0;         // metres
  double plate_thickness = 0.0;  // the thinnest static plate: deeper is through it (tunnelled)
  std::size_t asleep = 0;        // movers asleep at the end
  double mean_height = 0.0;      // mean z of the movers' centres at the end, m
};

constexpr int kPlausibilityWindow = 30;  // ticks: 0.5 s at 60 Hz

// How far a mover's voxels (dense index `mover`) reach into the static plates
// (their voxel boxes: the scenes' plates are full grids one voxel thick), in
// metres from a plate's front face (its grid +z face) to the deepest voxel's far side.
double deepestInStatic(const World& world, std::size_t mover);

class PlausibilityCheck {
 public:
  // Takes the movers' start: call before the first step.
  PlausibilityCheck(const World& world, const SceneSpec& spec);
  // After each World::step of `dt`.
  void tick(const World& world, double dt);
  Plausibility finish(const World& world) const;

 private:
  struct Track {
    Vec3 position, velocity;
    double stored = 0.0, real = 0.0;  // sums over the window's ticks it was stepped (not held)
    int ticks = 0;                    // those ticks
    bool too_fast = false;
  };
  Aabb bounds_;
  std::vector<EntityId> movers_;
  std::unordered_map<EntityId, Track> track_;
  Plausibility f_;
};

// One line: "NaN 0, outside 0, fastest 3.10 m/s (a fall allows 17.50), 0 too fast, ..."
std::string describe(const Plausibility& f);

}  // namespace stc::truth
