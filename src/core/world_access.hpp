// What tests, benches and the saved world's scene file read of a World
// beyond its public calls. Internal, as the types they return: a user of the
// installed headers neither needs nor sees them. World befriends
// WorldAccess for these alone.
#pragma once

#include "carried_state.hpp"
#include "pair_test.hpp"
#include "physics.hpp"
#include "sphere_tree_collision/world.hpp"
#include "sweep_and_prune.hpp"

#include <vector>

namespace stc {

struct WorldAccess {
  static const World::Parts& parts(const World& world) { return *world.parts_; }
  static World::Parts& parts(World& world) { return *world.parts_; }
};

// Narrow-phase results of the last step: pairTests(world)[0..world.pairCount()).
const std::vector<PairTest>& pairTests(const World& world);
// The broad phase: its pairs and boxes as of the last step.
const SweepAndPrune& broadPhase(const World& world);
// What the physics did in the last step: fast bodies swept back, solver stats.
const PhysicsReport& physicsReport(const World& world);

// What the next tick carries over from the last besides the bodies' rows, by
// dense index: a saved world's contact_state.
CarriedState carriedState(const World& world);
// The same put back into a World that holds the saved world's entities in
// the same dense order with the same ids (EntitySpec::id), before its first
// step: its next ticks at an unlimited budget are then the saved world's,
// bit for bit (docs/ros_interface.md, Saved worlds). Throws InputError
// naming the part and the field ("rest[2].body", "boxes", "banding",
// "broad_pairs", "carried[0].leaf", "warm[3]", ...) and then changes nothing.
void restoreCarried(World& world, const CarriedState& state);

}  // namespace stc
