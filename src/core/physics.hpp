// The World's physics: integrate, sweep, contacts and solve, keeping what lasts between
// ticks (warm-start impulses by entity id, sweep data, scratch), and the
// step context its phases read.
#pragma once

#include "contact_builder.hpp"
#include "contact_solver.hpp"
#include "continuous.hpp"
#include "pair_contact_cache.hpp"
#include "interior_field.hpp"
#include "shape_bounds.hpp"
#include "sphere_tree_collision/response_options.hpp"
#include "static_cover.hpp"
#include "workers.hpp"

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

namespace stc {

// One tick's view of the World, made once a tick (World::beginTick, as
// Box2D's step context): the tick's parameters and pointers to the World's
// flat arrays, so that the phases share one seam instead of long argument
// lists. Each phase reads what it names below; the pointers must outlive the
// call.
struct StepContext {
  double dt = 0.0;
  Vec3 gravity = Vec3::Zero();
  const ResponseOptions* options = nullptr;
  // Bodies by dense index, their shape ids, and the bounds and interior of
  // each shape id (built once per shape: World::addShape).
  std::vector<BodyState>* bodies = nullptr;
  const std::vector<std::uint32_t>* body_shapes = nullptr;
  const std::deque<ShapeBounds>* shape_bounds = nullptr;
  const std::deque<InteriorField>* interior_fields = nullptr;  // nullptr: no contacts from inside
  // The narrow phase's pairs: tests[0..*pair_count) (the count read when a
  // phase runs: the broad phase sets it), the dense indices of each test's
  // bodies, and their perceptual priorities (sweep: pair_bodies only).
  const std::vector<PairTest>* tests = nullptr;
  const std::size_t* pair_count = nullptr;
  const std::vector<std::array<std::uint32_t, 2>>* pair_bodies = nullptr;
  const std::vector<double>* priorities = nullptr;
  // Per pair: its PairContactCache entry when its contacts are carried over
  // this tick (its test resumed Colliding), else PairContactCache::kNone
  // (buildContacts; nullptr: every pair's contacts are built).
  const std::vector<std::uint32_t>* reused = nullptr;
  bool accept_unresolved = true;  // policy accept: unresolved pairs give contacts too
  // The narrow phase was limited this tick: an accepted unresolved pair keeps
  // the contacts of the deepest frontier it reached while its bodies stay put
  // (buildContacts; Physics::kFrontierTolerance).
  bool steady_frontier = false;
  SolveBudget budget;             // what the solver may spend (solve)
  std::vector<Contact>* contacts = nullptr;  // buildContacts' output, solve's input
  const Workers* workers = nullptr;  // threads of the parallel loops (nullptr: the caller's alone)
  // Entity ids by dense index, and the bodies held asleep this tick: the
  // solver keeps sleeping pairs' warm-start impulses (solve; nullptr: not).
  const std::vector<EntityId>* ids = nullptr;
  const std::vector<std::uint8_t>* held_asleep = nullptr;
  // Static bodies' covered faces, kept out of contact normals (buildContacts; nullptr: none).
  const StaticCover* static_cover = nullptr;
  // integrate: only the bodies flagged non-zero, the others left as they are
  // (held islands joined to the tick after the broad phase, island_levels.hpp;
  // nullptr: every body).
  const std::vector<std::uint8_t>* integrate_only = nullptr;
};

struct PhysicsReport {
  SweepStats sweep;
  SolveStats solve;
  // Accepted unresolved pairs that kept a deeper frontier's contacts this tick
  // (steady_frontier; Physics::kFrontierTolerance).
  std::size_t frontier_kept = 0;
  // Contacts measured against the other body's solid (kInteriorNode).
  std::size_t interior_contacts = 0;
};

class Physics {
 public:
  // Tick phase 1: positions, velocities (gravity), and which bodies are fast.
  // Reads dt, gravity, options, bodies, body_shapes, shape_bounds.
  void integrate(const StepContext& step);
  // After integrate: fast bodies need swept boxes in the broad phase, from
  // their start pose of the tick to their pose now.
  bool isFast(std::size_t body) const {
    return body < sweep_scratch_.fast.size() && sweep_scratch_.fast[body] != 0;
  }
  const Pose& startPose(std::size_t body) const { return start_[body]; }
  // Tick phase 2b, after the broad phase: sweep of the fast bodies against
  // their broad-phase partners pair_bodies[0..pair_count) (sweepFastBodies).
  // Reads options, bodies, pair_bodies, pair_count.
  void sweep(const StepContext& step);
  // Tick phase 4a: contacts of tests[0..pair_count) (pair_bodies: the same
  // pairs the sweep saw), plus the sweep's hit for a pair whose test gave no
  // contact proven at the leaves, into contacts; an unresolved pair's root
  // contact between a movable and a static body acts at the movable body's
  // deepest voxels (holdOnStatic).
  void buildContacts(const StepContext& step);
  // Tick phase 4b, after buildContacts: impulses on those contacts when
  // options->enabled, within budget.
  void solve(const StepContext& step);
  const PhysicsReport& lastReport() const { return report_; }
  void forget() { solver_.forget(); }
  // Pooled arrays cut to their size (World::releaseMemory); the caches of
  // carried contacts keep theirs.
  void releaseMemory();

  // Whether the response carries contacts over (ResponseOptions::reuse_tolerance).
  static bool reusesContacts(const ResponseOptions& options) {
    return options.enabled && options.reuse_tolerance > 0.0;
  }
  // Last tick's cache entry of the pair of bodies ia, ib (dense indices, in
  // the test's order) when it may be carried over now, else
  // PairContactCache::kNone. Reads ids, bodies, body_shapes, shape_bounds;
  // safe from many threads at once.
  std::uint32_t reusableEntry(const StepContext& step, std::uint32_t ia, std::uint32_t ib) const;
  const PairContactCache& pairCache() const { return pair_cache_; }
  // A saved world's (CarriedState): the carried contacts put back (keys as
  // the World's ids give them), and the solver, whose warm start it keeps.
  void restoreCarried(const std::vector<PairContactCache::Entry>& entries,
                      const std::vector<PairContactCache::Point>& points) {
    pair_cache_.restore(entries, points);
  }
  const ContactSolver& solver() const { return solver_; }
  ContactSolver& solver() { return solver_; }
  // Drops the carried contacts: the next tick builds every pair's (a static
  // body came or went, so covered faces may have changed; or the options did).
  void forgetReuse() {
    pair_cache_.clear();
    frontier_cache_.clear();
  }

  // A limited narrow phase reaches a pair's leaves in one tick and its root in
  // the next, as the time it gets and the gaze move: the frontier contacts
  // changed from tick to tick, and a pile under a varying budget flowed
  // (docs/error_vs_runtime.md). An accepted unresolved pair whose frontier
  // now is shallower than the one it had keeps that one's contacts, placed
  // anew, while no point of either body moved by more than this fraction of
  // the smaller leaf radius since they were built.
  static constexpr double kFrontierTolerance = 0.5;

 private:
  // A builder (its scratch) and the contacts of each chunk of the pairs
  // (parallel contact building); capacity kept between ticks.
  std::vector<ContactBuilder> builders_;
  struct alignas(64) ChunkContacts {  // a line of its own: its end moves with each contact
    std::vector<Contact> contacts;
    PairContactCache::Pending reuse;  // the chunk's pairs' cache entries for the next tick
    PairContactCache::Pending frontier;  // ... and their frontier entries (steady_frontier)
    std::size_t frontier_kept = 0;       // its pairs that kept a deeper frontier's contacts
  };
  // Also records the pairs' cache entries into chunk.reuse when step.reused is
  // set, and their frontier entries into chunk.frontier (counting the kept ones)
  // when step.steady_frontier is set.
  void appendContacts(const StepContext& step, std::size_t first, std::size_t last, ContactBuilder& builder,
                      std::vector<Contact>& out, ChunkContacts& chunk) const;
  ReuseBody reuseBody(const StepContext& step, std::uint32_t index) const;
  // Root-sphere contacts of an unresolved pair of a movable and a static
  // body whose boxes touch, out[before..], as the movable body's deepest
  // voxels along the normal (physics.cpp).
  void holdOnStatic(const StepContext& step, std::uint32_t ia, std::uint32_t ib, std::size_t before,
                    std::vector<Contact>& out) const;
  // The sweep's hit of pair i (bodies ia, ib) merged into the pair's contacts
  // out[before..] when the sweep held a body back there and none of them
  // stops that approach already; at most max_contacts_per_pair.
  void appendSweepHit(const StepContext& step, std::uint32_t ia, std::uint32_t ib, std::size_t i,
                      std::size_t before, std::vector<Contact>& out) const;

  std::vector<ChunkContacts> chunk_contacts_;
  std::size_t builder_turn_ = 0;
  ContactSolver solver_;
  PairContactCache pair_cache_;  // contacts carried over between ticks
  PairContactCache frontier_cache_;  // each pair's deepest contacts while it stays put (steady_frontier)
  std::vector<const PairContactCache::Pending*> reuse_pending_;  // the chunks' entries, for commit
  double gravity_speed_ = 0.0;  // |g| dt of the last integrate
  std::vector<Pose> start_;
  std::vector<Vec3> start_v_, start_w_;  // the soft step's: velocities at the tick's start
  std::vector<const ShapeBounds*> body_bounds_;
  SweepScratch sweep_scratch_;
  std::vector<std::int32_t> sweep_hit_of_pair_;  // body whose sweep hit that pair, or -1
  PhysicsReport report_;
};

}  // namespace stc
