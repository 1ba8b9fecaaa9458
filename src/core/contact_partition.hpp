// Spatial partition of the solver's contacts into blocks that may run side by
// side, so a pass waits for the other threads a few times (once or twice:
// SolverThreadPlan::planStages), not once per graph colour (a small scene's
// colours are too small to split: docs/parallel.md).
//
// The unit is a group: the contacts of one body pair, solved one after the
// other by one thread. The movable bodies are cut into slabs along the widest
// axis of their centres, each slab touching about as many contacts. A group
// whose movable bodies lie in one slab s goes to block s of stage 0; a group
// across the cut between slabs s and s + 1 to block s of stage 1 (s even) or
// of stage 2 (s odd); any other group to stage 3's single block. The blocks
// of one stage share no movable body, so they may run at once on any
// threads; a block's groups run in the order they were given (the serial
// solver's, up the contact graph from the ground); the stages run one after
// the other. Static bodies do not count (nothing writes their velocity).
//
// The slab count depends on the groups and the bodies' positions, never on
// the thread count, so neither does the order, nor the result's bits.
#pragma once

#include "sphere_tree_collision/body.hpp"

#include <cstdint>
#include <limits>
#include <vector>

namespace stc {

struct SolverGroup {
  static constexpr std::uint32_t kStatic = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t a = kStatic, b = kStatic;  // dense body indices; kStatic: a body that never moves
  std::uint32_t rows = 1;                  // its contacts: the work it costs a pass
};

class ContactPartition {
 public:
  static constexpr std::uint32_t kStages = 4;
  static constexpr std::uint32_t kMaxSlabs = 16;
  // At most groups / this many slabs: a smaller block costs more to hand to
  // a thread than it saves.
  static constexpr std::size_t kMinGroupsPerSlab = 32;
  // Fewer slabs are taken while more of the groups than these shares cross
  // a cut (stages 1-2) or span more than one (stage 3): slabs thinner than
  // a few bodies put most of the work into the later stages.
  static constexpr double kMaxCrossingShare = 0.25;
  static constexpr double kMaxSpanningShare = 0.03;

  // Blocks the groups of `bodies` (dense indices); no allocation once warm.
  void assign(const std::vector<SolverGroup>& groups, const std::vector<BodyState>& bodies);
  // Capacity for up to `groups` groups of `bodies` bodies, grown geometrically:
  // the solver sizes it by its rows, in the tick they grow, so a later tick with
  // more groups (or the first with enough to cut) allocates nothing.
  void reserve(std::size_t groups, std::size_t bodies);
  std::uint32_t slabs() const { return slabs_; }
  // Block of each group: stage * slabs() + slab (stage 3: 3 * slabs()).
  const std::vector<std::uint32_t>& blocks() const { return block_; }
  // Block ids are below this (stage 3 uses only 3 * slabs()).
  std::uint32_t blockCount() const { return kStages * slabs_; }
  std::uint32_t stageOf(std::uint32_t block) const { return block / slabs_; }
  // Groups of stages 1 to 3 after the last assign.
  std::size_t crossing() const { return crossing_; }

 private:
  // The blocks for `slabs` slabs from the body bins; the groups crossing a
  // cut and those spanning more than one counted.
  void blockFor(std::uint32_t slabs, const std::vector<SolverGroup>& groups, std::size_t& crossing,
                std::size_t& spanning);

  static constexpr std::uint32_t kBins = 1024;  // the widest axis in bins, cut between bins
  std::vector<std::uint32_t> bin_;   // per body: its bin along the axis
  std::vector<std::uint32_t> bin_weight_, slab_of_bin_;
  std::vector<std::uint32_t> block_;  // by group
  std::uint32_t slabs_ = 1;
  std::size_t crossing_ = 0;
};

}  // namespace stc
