// The solver's warm start between ticks (ContactSolver, paper 3.5): each
// body pair's manifold of the last solve, its points' impulses by feature id
// and by place in body A's frame, and the manifolds of sleeping pairs, held
// apart until they wake. What the passes start from; the passes themselves
// stay in ContactSolver.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/types.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace stc {

class WarmStartCache {
 public:
  // Last tick's manifold of a body pair: its points' impulses, by feature id
  // (the leaf sphere pair a point was built from) and position in A's frame.
  struct Point {
    std::int32_t node_a = 0, node_b = 0;
    Vec3 local_a = Vec3::Zero();
    double normal = 0.0;
    Vec3 friction = Vec3::Zero();  // world frame
  };
  struct Manifold {
    std::uint64_t pair = 0;              // entity ids a, b packed: the sort key
    std::uint32_t first = 0, count = 0;  // its points in the store's points
    std::uint32_t index_a = 0, index_b = 0;  // the bodies' dense indices when it was solved
    Vec3 rolling = Vec3::Zero();             // its rolling-resistance impulse, world frame
  };
  // At most this many points of a manifold are kept for the warm start.
  static constexpr std::uint32_t kMaxPoints = 32;
  // A store, for a saved world (CarriedState): its manifolds (sorted by
  // pair), each with its points [first, first + count) of the points given.
  struct Store {
    const std::vector<Manifold>* manifolds = nullptr;
    const std::vector<Point>* points = nullptr;
  };
  // Last solve's store and the held store (sleeping pairs').
  Store solved() const { return {&manifolds_, &points_}; }
  Store held() const { return {&held_manifolds_, &held_points_}; }
  // Both put back: pairs and indices as the loaded world's ids and dense
  // indices give them, sorted here; counts of at most kMaxPoints (checked by
  // the caller).
  void restore(std::vector<Manifold> solved, std::vector<Point> solved_points, std::vector<Manifold> held,
               std::vector<Point> held_points);
  void clear();  // drop every impulse (ContactSolver::forget)
  bool empty() const { return manifolds_.empty() && held_manifolds_.empty(); }

  // Bodies held out of the solve because they sleep (by dense index, non-zero:
  // held) and the bodies' entity ids: a manifold of last tick's store that
  // this tick did not solve is kept while both its bodies are out of the
  // solve and one of them sleeps, so a woken pile starts from the impulses
  // it fell asleep with, not cold (nullptr: none kept). Valid for the
  // following solves.
  void keepWhileHeld(const std::vector<EntityId>* ids, const std::vector<std::uint8_t>* held) {
    ids_ = ids;
    held_bodies_ = held;
  }

  // A pair's manifold for the warm start, its points in `points`: of last
  // solve, else of the held store (the two never hold one pair); nullptr
  // when neither has it.
  const Manifold* find(std::uint64_t pair, const Point*& points) const;

  // Both stores that swap every tick grow with the rows in the tick that
  // needs them (no allocation in a later tick with more manifolds).
  void reserve(std::size_t rows);
  // After a solve, the next store: sized first, then each manifold's points
  // and the manifold written at their own places (so by manifold in
  // parallel), then made the store the next solve starts from.
  void beginNext(std::size_t points, std::size_t manifolds);
  // Point `at` of the next store: contact c's feature id, its place in the
  // frame of A (at `pose_a`) and the impulses it took.
  void keepPoint(std::size_t at, const Contact& c, const Pose& pose_a, double normal, const Vec3& friction);
  void keepManifold(std::size_t m, const Manifold& manifold) { next_manifolds_[m] = manifold; }
  // The next store sorted and swapped in; the held store updated first from
  // `out_of_solve` (per body: static or held in this solve) and last solve's.
  void commitNext(const std::vector<std::uint8_t>& out_of_solve);
  // The same after a solve without contacts: only the sleepers' manifolds stay.
  void commitNone(const std::vector<std::uint8_t>& out_of_solve);

 private:
  static bool byPair(const Manifold& x, const Manifold& y) { return x.pair < y.pair; }
  // A manifold stays held while both bodies are still there (a despawn
  // moves indices: the ids must match) and out of the solve, one asleep.
  bool stillHeld(const Manifold& m, const std::vector<std::uint8_t>& out_of_solve) const;
  // The held store keeps what still sleeps and gains last solve's manifolds
  // whose pairs now do; then the next store replaces last solve's.
  void keepHeldManifolds(const std::vector<std::uint8_t>& out_of_solve);
  void dropWoken(const std::vector<std::uint8_t>& out_of_solve);
  void holdFallenAsleep(const std::vector<std::uint8_t>& out_of_solve);

  std::vector<Point> points_, next_points_;
  std::vector<Manifold> manifolds_, next_manifolds_;  // last solve's and this one's, sorted by pair
  // Manifolds of sleeping pairs, sorted by pair, their points in held_points_.
  // Kept apart from the solved ones, so a tick of a mostly sleeping pile
  // copies none of them: only a wake or a despawn (an entry that no longer
  // qualifies) compacts the store, and only a pair falling asleep adds to it.
  std::vector<Point> held_points_, held_points_scratch_;
  std::vector<Manifold> held_manifolds_, held_merge_;
  const std::vector<EntityId>* ids_ = nullptr;
  const std::vector<std::uint8_t>* held_bodies_ = nullptr;
};

}  // namespace stc
