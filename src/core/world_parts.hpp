// World::Parts: what a World is made of (world.hpp holds it by pointer): the
// shapes (ShapeLibrary) and the entities' rows (EntityTable), what follows
// each add and remove, fracture (WorldFracture) and the phases, in tick
// order. World's calls forward here (one pointer hop each).
#pragma once

#include "sphere_tree_collision/world.hpp"

#include "entity_table.hpp"
#include "island_levels.hpp"
#include "islands.hpp"
#include "narrow_chunks.hpp"
#include "pair_test.hpp"
#include "physics.hpp"
#include "shape_library.hpp"
#include "static_cover.hpp"
#include "sweep_and_prune.hpp"
#include "workers.hpp"

#include <array>
#include <memory>
#include <vector>

namespace stc {

struct CarriedState;  // carried_state.hpp
class WorldFracture;  // world_fracture.hpp
struct TickContext;   // tick_context.hpp

struct World::Parts {
  Parts(World& owner, const WorldConfig& config);
  ~Parts();
  Parts(const Parts&) = delete;
  Parts& operator=(const Parts&) = delete;

  // World's calls that do more than read a member (world*.cpp).
  ShapeId addShape(const std::string& key, VoxelShape shape);
  EntityId addEntity(const EntitySpec& spec);
  void validateEntity(const EntitySpec& spec) const;
  bool removeEntity(EntityId id);
  void clear();
  void releaseMemory();
  std::vector<EntityId> breakEntity(EntityId id, const Vec3& point, const Vec3& normal);
  TickReport step(double dt, const Budget& budget);
  void setClock(SecondsClock clock);
  void setScheduler(const SchedulerOptions& options);
  void setResponse(const ResponseOptions& options);
  void setGravity(const Vec3& gravity);
  bool wake(EntityId id);
  bool isSleeping(EntityId id) const;
  bool isRestless(EntityId id) const;
  ResponseLevel responseLevel(EntityId id) const;
  CarriedState carriedState() const;
  void restoreCarried(const CarriedState& state);
  void settleBroadPhase();

  // The tick's context, made once at its start (tick_context.hpp), then the
  // phases in tick order; each times itself into the report (PhaseTimer).
  TickContext beginTick(double dt, const Budget& budget, TickReport& report);
  void integrate(TickContext& tick);
  void broadPhase(TickContext& tick);  // also sets up the pair tests of its pairs
  void continuousCollision(TickContext& tick);
  void narrowPhase(TickContext& tick);  // notes when the scheduler stopped (what follows is not interruptible)
  void response(TickContext& tick);
  // First and last: removes bodies beyond the limits; bodies flagged in
  // `unchanged` (held through the tick) are not looked at again.
  void quarantine(TickReport& report, const std::vector<std::uint8_t>* unchanged = nullptr);
  // Fracture after the response, and the breaks that waited, at the tick's
  // start (WorldFracture::fracture / breakPending, world_fracture.cpp); their
  // time counts in TickFracture::fracture_s.
  void fracture(TickContext& tick);
  void breakPending(TickContext& tick);
  Aabb boxOf(std::size_t index) const;
  Aabb sweptBoxOf(std::size_t index) const;
  void invalidateLastTick();
  // Island levels (world_levels.cpp). Whether the response is limited this
  // tick; the islands ranked and the ones beyond the allowance held
  // (before integrate); held islands a moving body reaches joined to the tick
  // and integrated (after the broad phase's pairs); after the tick, what a
  // unit of cost took and what the phases that must run took, for the next.
  static bool responseLimited(const Budget& budget);
  void chooseLevels(const Budget& budget, TickReport& report);
  void joinHeldIslands(TickContext& tick);
  void learnLevelCosts(double must_run_s, double response_mandatory_s, const TickReport& report);
  // The solver's "held" bodies: asleep or held by their level (for its warm-start store).
  const std::vector<std::uint8_t>& outOfStep();
  bool setUpPairTests();  // bodies of the broad phase's pairs; true when a sleeping island woke

  // The World that holds these parts, set again when it moves: WorldFracture
  // works through its public calls.
  World* world_;
  WorldConfig config_;
  Workers workers_;  // before the phases that use it
  ShapeLibrary shapes_;  // by shape id
  EntityTable rows_;     // the entities' rows, by dense index
  StaticCover static_cover_;  // static bodies' faces other static bodies cover, by dense index

  SweepAndPrune broad_phase_;
  std::vector<Aabb> boxes_;  // this tick's box of each body, by dense index (pooled)
  std::vector<EntityId> partners_;  // removeEntity: the broad-phase partners of the removed body (pooled)
  // The narrow phase's chunks, as many as it ever cuts (narrow_chunks.hpp): a
  // scheduler each and the arena of its pair tests' hits; in a vector made
  // once (the pair tests point at the arenas).
  std::vector<NarrowChunk> narrow_chunks_;
  std::size_t narrow_chunks_used_ = 1;  // by the last narrow phase
  Perception perception_;
  std::vector<PairTest> pair_tests_;  // pooled: capacity kept between ticks
  std::size_t pair_count_ = 0;
  std::vector<std::array<std::uint32_t, 2>> pair_bodies_;  // dense indices of each pair test's bodies
  std::vector<std::uint8_t> pair_tested_;  // setUpPairTests: per broad-phase pair, not static-static
  // setUpPairTests: each broad-phase pair's ids and dense indices as last
  // looked up, by its place in the pair list (a pair mostly keeps its place
  // from tick to tick); emptied when a removal moves dense indices.
  struct SeenPair {
    BroadPair ids{0, 0};  // {0, 0} is no pair: a miss
    std::array<std::uint32_t, 2> indices{};
  };
  std::vector<SeenPair> pairs_seen_;
  std::vector<double> pair_priority_;  // perceptual priority of each pair test (0 without gaze)
  std::vector<std::uint32_t> pair_reused_;  // each pair's carried-over contacts (PairContactCache), or kNone
  std::vector<Contact> contacts_;
  Physics physics_;  // integration and response (response.hpp), warm-start state
  Islands islands_;  // which bodies sleep, indexed like bodies_
  IslandLevels levels_;  // which awake islands are held this tick, indexed like bodies_
  // Learnt from timed ticks (world_levels.cpp): seconds of the response's
  // mandatory part per unit of island cost, and of the phases that must run.
  double cost_unit_s_ = 0.0;
  double must_run_s_ = 0.0;
  std::vector<std::uint8_t> out_of_step_;  // outOfStep (pooled)
  SecondsClock clock_ = steadySeconds;
  std::int64_t clock_check_every_ = BudgetTracker::kDefaultCheckEvery;  // of clock_ (setClock)
  double reserve_s_ = 0.0;  // TickReport::budget.reserve_s of the next tick
  std::vector<QuarantinedEntity> quarantined_;  // by the last step
  std::vector<std::uint8_t> held_through_tick_;  // step: Islands::held() before endTick (pooled)
  std::unique_ptr<WorldFracture> fracture_;  // its queue, tree costs and what broke
};

}  // namespace stc
