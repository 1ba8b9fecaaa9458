// SweepAndPrune: the I-COLLIDE broad phase (paper 3.2). Sorted endpoint lists
// per axis kept sorted by insertion sort each tick (temporal coherence); the
// overlap-pair set is updated by the swaps, never rebuilt by an all-pairs pass
// after the first sort. Each axis's list is split into bands along another
// axis so that endpoints only pass boxes near them (sweep_and_prune.cpp).
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace stc {

// Broad-phase pair, ids ordered first < second.
struct BroadPair {
  EntityId first;
  EntityId second;
  bool operator==(const BroadPair& o) const { return first == o.first && second == o.second; }
};

class SweepAndPrune {
 public:
  // Add/remove between ticks; pairs() reflects them after the next update(),
  // which drops removed boxes at a cost that follows their bands and pairs.
  // Adding an existing id or removing an unknown one throws InputError("id");
  // a non-finite box or min > max throws InputError("box"). Ids are arbitrary.
  void add(EntityId id, const Aabb& box);
  void remove(EntityId id);
  bool contains(EntityId id) const;
  // Set the box an entity will have at the next update(). Unknown id throws
  // InputError("id"), a bad box InputError("box").
  void setBox(EntityId id, const Aabb& box);
  // Re-sort the endpoint arrays (insertion sort) and update the pair set.
  void update();
  // Pairs whose boxes overlap on all three axes (touching counts, as in
  // Aabb::overlaps) as of the last update(), in no particular order.
  const std::vector<BroadPair>& pairs() const { return pairs_; }
  // The other entities of `id`'s pairs as of the last update() (one may
  // have been removed since), into *out (emptied first): a walk of its own
  // pairs, not of all. Unknown id throws InputError("id").
  void partnersOf(EntityId id, std::vector<EntityId>* out) const;
  std::size_t size() const;
  // The box last given for an entity (by add or setBox); unknown id throws InputError("id").
  Aabb box(EntityId id) const;
  // Rebuilt for the boxes it holds now, then updated (World::releaseMemory):
  // its per-slot arrays and lists keep the size of its peak otherwise. The
  // pairs stay the same set, perhaps in another order.
  void releaseMemory();
  // The bands as last chosen: per axis's lists the map of a coordinate on
  // the band axis to a band (origin, scale, top: band = min(max((v - origin)
  // * scale, 0), top)), and the boxes they were chosen for (chosen again
  // when the count doubles or halves). Which band a box is in decides the
  // order new pairs are found in.
  struct Banding {
    std::array<double, 3> origin{}, scale{}, top{};
    std::uint64_t chosen_for = 0;
    // Per list, each band's endpoints in their order (id << 1 | is_max):
    // endpoints of equal value stay in the order they came in (a static
    // floor's pieces share edges), which decides the order of their pairs.
    std::array<std::vector<std::vector<std::uint64_t>>, 3> endpoints;
    // The boxes' ids in the order of their slots: boxes entering bands in
    // one update are swept in it (a despawn frees a slot a spawn takes).
    std::vector<EntityId> slots;
  };
  Banding banding() const;
  // Updated at least once, and nothing added or removed since: its pairs
  // are those of its boxes (what restore() needs).
  bool settled() const;
  // A saved world's broad phase (CarriedState): rebuilt for the boxes it
  // holds now with these bands, its pairs then in `order`, as the saved one
  // had them after its last update (the next updates then find and drop
  // pairs in the same order). Throws InputError("banding") for bands that
  // are not a map to at most 256 bands or endpoints that are not each band's
  // in order or slots that are not its boxes' ids, InputError("pairs") when
  // `order` is not the pairs of the boxes; then nothing changes.
  void restore(const Banding& banding, const std::vector<BroadPair>& order);
  // Endpoint swaps done by the last update(): the measure of coherence.
  std::size_t lastSwapCount() const { return last_swaps_; }

  SweepAndPrune();
  ~SweepAndPrune();
  SweepAndPrune(SweepAndPrune&&) noexcept;
  SweepAndPrune& operator=(SweepAndPrune&&) noexcept;

 private:
  struct Impl;  // endpoint arrays and overlap bookkeeping (sweep_and_prune.cpp)
  std::unique_ptr<Impl> impl_;
  std::vector<BroadPair> pairs_;
  std::size_t last_swaps_ = 0;
};

}  // namespace stc
