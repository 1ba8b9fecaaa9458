// WorldFracture: the World's part of fracture (fracture.hpp), with its own
// state: which bodies break after a tick's response, the breaks waiting for
// their pieces' trees, what a tree costs to build, and what broke since the
// last step began. It works through the World's public interface (the
// pieces are added and the parent removed as any entity is); the World owns
// one and calls it from step() and breakEntity().
#pragma once

#include "fracture.hpp"
#include "grow_capacity.hpp"
#include "deadline.hpp"
#include "sphere_tree_collision/world.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace stc {

class WorldFracture {
 public:
  // World::breakEntity.
  std::vector<EntityId> breakEntity(World& world, EntityId id, const Vec3& point, const Vec3& normal);
  // After the response: bodies hit harder than their strength are queued. A
  // break is made once its pieces' trees exist; a tree is built only when
  // its estimated cost fits before the tick's deadline, but for one tree at
  // each tick's start (breakPending), so the queue always moves. Both take
  // the clock at their start and return it at their end, reading it only
  // when there is something to break.
  double fracture(World& world, const SecondsClock& clock, double now, const Deadline& tick_end,
                  TickReport& report);
  double breakPending(World& world, const SecondsClock& clock, double now, const Deadline& tick_end,
                      TickReport& report);
  // A step begins: broken() empties.
  void newStep() { broken_.clear(); }
  void releaseMemory() { dropSpareCapacity(hits_); }
  const std::vector<BrokenEntity>& broken() const { return broken_; }

  // A break waiting for its pieces' trees: the plane in the body's grid
  // frame, so the split is the same whenever it is made.
  struct PendingBreak {
    EntityId id = kInvalidEntity;
    SplitPlane plane;
  };
  // Oldest first; a saved world carries them (carriedState, world_access.hpp).
  const std::vector<PendingBreak>& pendingBreaks() const { return pending_breaks_; }
  void restorePending(std::vector<PendingBreak> breaks) { pending_breaks_ = std::move(breaks); }

 private:
  void breakQueued(World& world, const SecondsClock& clock, const Deadline& trees_until, bool one_tree_anyway,
                   TickReport& report);
  // The fracture plane of an impact at `point` along `normal` (world frame)
  // on body `index`, in its grid frame (fracturePlane).
  static SplitPlane gridPlaneOf(const World& world, std::size_t index, const Vec3& point, const Vec3& normal);
  // The split of body `index` by `plane` (its grid frame): its pieces, or
  // nothing when it stays whole.
  static std::vector<VoxelPiece> piecesOf(const World& world, std::size_t index, const SplitPlane& plane);
  // A piece's shape: the one with its voxels, or std::nullopt (*key: the key to add it by).
  static std::optional<ShapeId> findPieceShape(const World& world, const VoxelShape& voxels, std::string* key);
  // Replaces body `index` by `pieces`; their trees are built here if missing.
  std::vector<EntityId> placePieces(World& world, std::size_t index, std::vector<VoxelPiece>& pieces);

  std::vector<PendingBreak> pending_breaks_;
  TreeCostEstimate tree_cost_;  // of the pieces' trees built so far
  std::vector<BrokenEntity> broken_;  // since the last step began
  // Contact impulses on each body this tick (by dense index; ticks with a
  // breakable body in contact only), pooled.
  struct BodyHits {
    double impulse = 0.0;          // summed, N s
    double hardest_impulse = 0.0;  // of the contact with the largest impulse
    std::int32_t hardest = -1;     // that contact
  };
  std::vector<BodyHits> hits_;
};

}  // namespace stc
