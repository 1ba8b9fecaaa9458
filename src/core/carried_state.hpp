// CarriedState: what a World carries from one tick to the next besides its
// bodies' rows, for a saved world (scene_file.hpp, contact_state) to go on
// as it would have: the awake bodies' rest timers and balls, the broad
// phase's boxes, bands and pair order, the contacts carried between ticks
// (PairContactCache), the solver's warm-start impulses and the fractures
// waiting for their pieces' trees. Bodies by dense
// index, so that a World loaded in the same order takes it whatever its ids.
#pragma once

#include "fracture.hpp"
#include "islands.hpp"
#include "pair_contact_cache.hpp"
#include "sphere_tree_collision/types.hpp"
#include "sweep_and_prune.hpp"
#include "warm_start_cache.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace stc {

struct CarriedState {
  // Each awake movable body's rest test and timer (islands.hpp).
  struct Rest {
    std::uint32_t body = 0;
    BodyRest state;
  };
  std::vector<Rest> rest;
  std::uint32_t next_group = 1;  // the next island to fall asleep takes this group

  // Per body, the box the broad phase holds; its bands (SweepAndPrune::Banding);
  // its pairs in their order, as dense indices. No boxes: the broad phase
  // starts afresh (saved with entities added or removed since its last
  // update: SweepAndPrune::settled; World::settleBroadPhase brings it up to
  // them first).
  std::vector<Aabb> boxes;
  SweepAndPrune::Banding banding;
  std::vector<std::array<std::uint32_t, 2>> broad_pairs;

  // The contacts carried over to the next tick: each entry's bodies (in the
  // pair's order) and its points entries[k].first.. (key ignored).
  struct CarriedEntry {
    std::uint32_t a = 0, b = 0;
    PairContactCache::Entry entry;
  };
  std::vector<CarriedEntry> carried;
  std::vector<PairContactCache::Point> carried_points;

  // The warm start: the last solve's manifolds, then the held store's
  // (sleeping pairs), each with its bodies and its points
  // manifold.first.. in warm_points (pair and indices ignored).
  struct Warm {
    std::uint32_t a = 0, b = 0;
    bool held = false;
    WarmStartCache::Manifold manifold;
  };
  std::vector<Warm> warm;
  std::vector<WarmStartCache::Point> warm_points;

  // Fractures waiting for their pieces' trees (a tick budget ran out),
  // oldest first: the body and its fracture plane in its grid frame
  // (WorldFracture), made at the loaded world's next tick.
  struct Break {
    std::uint32_t body = 0;
    SplitPlane plane;
  };
  std::vector<Break> breaks;
};

}  // namespace stc
