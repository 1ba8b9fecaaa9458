// The solver's manifolds in block order (contact_partition.hpp) and the loop
// that runs a pass over them stage by stage, each stage's blocks in parallel.
#include "sphere_tree_collision/contact_solver.hpp"

#include "grow_capacity.hpp"

#include <limits>

namespace stc {
namespace {

// The slabs a block's groups may hold movable bodies of (bit s: slab s): its
// own in stage 0, the two at its cut in stages 1 and 2, any in stage 3
// (ContactPartition).
std::uint32_t slabsOfBlock(std::uint32_t block, std::uint32_t slabs) {
  const std::uint32_t stage = block / slabs;
  const std::uint32_t slab = block % slabs;
  if (stage == 0) return 1u << slab;
  if (stage < 3) return 3u << slab;
  return ~0u;
}

// after[k] for runs[0, count): the earlier runs of an earlier stage that
// share a slab with run k. Blocks of one stage share no movable body, so
// these are all a run must wait for to see its bodies as the serial order would.
template <typename Run>
void waitMasks(const Run* runs, std::size_t count, std::uint32_t slabs, std::uint64_t* after) {
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint32_t stage = runs[k].block / slabs;
    const std::uint32_t mine = slabsOfBlock(runs[k].block, slabs);
    std::uint64_t wait = 0;
    for (std::size_t j = 0; j < k; ++j) {
      if (runs[j].block / slabs < stage && (slabsOfBlock(runs[j].block, slabs) & mine) != 0) {
        wait |= std::uint64_t{1} << j;
      }
    }
    after[k] = wait;
  }
}

}  // namespace

void ContactSolver::blockManifolds(const std::vector<BodyState>& bodies, const std::vector<Contact>& contacts) {
  // Groups: the manifolds, runs of one body pair in order_ (a pair's contacts
  // are adjacent, as ContactBuilder emits them, and stay so in the order from
  // the ground, which is stable).
  groups_.clear();
  group_first_.clear();
  levels_.clear();  // the levels met, in that order
  // Sized by the contacts, in the tick they grow (no allocation in a later
  // tick with more manifolds or levels and no more contacts).
  for (std::vector<std::uint32_t>* v : {&group_first_, &group_order_, &block_order_, &manifold_start_, &cursor_}) {
    growCapacity(*v, order_.size() + 1);
  }
  growCapacity(groups_, order_.size());
  growCapacity(manifolds_, order_.size());
  growCapacity(levels_, order_.size());
  for (std::size_t p = 0; p < order_.size(); ++p) {
    const Contact& c = contacts[order_[p]];
    const int level = levelOf(c);
    if (levels_.empty() || levels_.back() != level) levels_.push_back(level);
    if (p > 0) {
      const Contact& previous = contacts[order_[p - 1]];
      if (c.index_a == previous.index_a && c.index_b == previous.index_b) continue;
    }
    SolverGroup group;
    group.a = bodies[c.index_a].is_static ? SolverGroup::kStatic : c.index_a;
    group.b = bodies[c.index_b].is_static ? SolverGroup::kStatic : c.index_b;
    groups_.push_back(group);
    group_first_.push_back(static_cast<std::uint32_t>(p));
  }
  group_first_.push_back(static_cast<std::uint32_t>(order_.size()));
  for (std::size_t g = 0; g < groups_.size(); ++g) groups_[g].rows = group_first_[g + 1] - group_first_[g];
  partition_.assign(groups_, bodies);

  // Manifolds by block, stable (counting sort), then their contacts in that order.
  const std::vector<std::uint32_t>& block = partition_.blocks();
  const std::uint32_t block_count = partition_.blockCount();
  block_manifold_start_.assign(block_count + 1, 0);
  for (std::size_t g = 0; g < groups_.size(); ++g) ++block_manifold_start_[block[g] + 1];
  for (std::size_t b = 1; b < block_manifold_start_.size(); ++b) block_manifold_start_[b] += block_manifold_start_[b - 1];
  cursor_.assign(block_manifold_start_.begin(), block_manifold_start_.end() - 1);  // fill positions
  group_order_.resize(groups_.size());
  for (std::uint32_t g = 0; g < groups_.size(); ++g) group_order_[cursor_[block[g]]++] = g;
  block_order_.clear();
  manifold_start_.clear();
  manifolds_.clear();
  for (const std::uint32_t g : group_order_) {
    manifold_start_.push_back(static_cast<std::uint32_t>(block_order_.size()));
    manifolds_.push_back(groups_[g]);
    for (std::uint32_t p = group_first_[g]; p < group_first_[g + 1]; ++p) block_order_.push_back(order_[p]);
  }
  manifold_start_.push_back(static_cast<std::uint32_t>(block_order_.size()));
  order_.swap(block_order_);

  // A pass's runs: the non-empty blocks, stage by stage.
  const std::uint32_t slabs = partition_.slabs();
  pass_runs_.clear();
  pass_stage_start_.clear();
  for (std::uint32_t b = 0; b < block_count; ++b) {
    if (b % slabs == 0) pass_stage_start_.push_back(static_cast<std::uint32_t>(pass_runs_.size()));
    if (block_manifold_start_[b + 1] > block_manifold_start_[b]) {
      pass_runs_.push_back(ManifoldRun{block_manifold_start_[b], block_manifold_start_[b + 1], b});
    }
  }
  pass_stage_start_.push_back(static_cast<std::uint32_t>(pass_runs_.size()));
  static_assert(ContactPartition::kStages * ContactPartition::kMaxSlabs <= Team::kMaxBlocks, "a pass is one round");
  growCapacity(pass_after_, pass_runs_.size());
  pass_after_.resize(pass_runs_.size());
  waitMasks(pass_runs_.data(), pass_runs_.size(), slabs, pass_after_.data());

  // Shock propagation's runs: within a block the manifolds are in the order
  // from the ground, so each level takes the next run of every block, stage
  // by stage. Restricted to one level, the blocks of a stage still share no
  // movable body.
  constexpr int kUnreached = std::numeric_limits<int>::max();
  level_runs_.clear();
  level_stage_start_.clear();
  cursor_.assign(block_manifold_start_.begin(), block_manifold_start_.end() - 1);
  for (const int level : levels_) {
    if (level == kUnreached) break;  // nothing static below: no shock to pass on
    for (std::uint32_t b = 0; b < block_count; ++b) {
      if (b % slabs == 0) level_stage_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
      std::uint32_t end = cursor_[b];
      while (end < block_manifold_start_[b + 1] && levelOf(contacts[order_[manifold_start_[end]]]) == level) ++end;
      if (end > cursor_[b]) level_runs_.push_back(ManifoldRun{cursor_[b], end, b});
      cursor_[b] = end;
    }
  }
  if (!level_stage_start_.empty()) level_stage_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
  growCapacity(level_after_, level_runs_.size());
  level_after_.resize(level_runs_.size());
  for (std::size_t level = 0; level < shockLevels(); ++level) {  // masks relative to the level's first run
    const std::uint32_t first = level_stage_start_[level * ContactPartition::kStages];
    const std::uint32_t end = level_stage_start_[(level + 1) * ContactPartition::kStages];
    waitMasks(level_runs_.data() + first, end - first, slabs, level_after_.data() + first);
  }
}

void ContactSolver::runStages(const ManifoldRun* runs, const std::uint64_t* after, const std::uint32_t* stage_first,
                              RangeFn manifolds) const {
  const std::size_t count = stage_first[ContactPartition::kStages];
  std::size_t total = 0;
  for (std::size_t k = 0; k < count; ++k) total += runs[k].end - runs[k].first;
  if (team_ == nullptr || count < 2 || total < task_manifolds_) {
    for (std::size_t k = 0; k < count; ++k) manifolds(runs[k].first, runs[k].end);
    return;
  }
  team_->forBlocksAfter(count, after, stage_first, ContactPartition::kStages,
                        [&](std::size_t k, std::size_t) { manifolds(runs[k].first, runs[k].end); });
}

void ContactSolver::forEachStage(RangeFn manifolds) {
  if (pass_stage_start_.empty()) return;
  runStages(pass_runs_.data(), pass_after_.data(), pass_stage_start_.data(), manifolds);
}

void ContactSolver::forEachStageOfLevel(std::size_t level, RangeFn manifolds) {
  const std::size_t first = level * ContactPartition::kStages;
  const std::uint32_t base = level_stage_start_[first];
  std::uint32_t stage_first[ContactPartition::kStages + 1];
  for (std::size_t s = 0; s <= ContactPartition::kStages; ++s) stage_first[s] = level_stage_start_[first + s] - base;
  runStages(level_runs_.data() + base, level_after_.data() + base, stage_first, manifolds);
}

}  // namespace stc
