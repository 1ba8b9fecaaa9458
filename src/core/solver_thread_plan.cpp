// The solver's thread plan (solver_thread_plan.hpp): the manifolds in block
// order (contact_partition.hpp) and the loops that run a pass over them stage
// by stage, each stage's blocks in parallel.
#include "solver_thread_plan.hpp"

#include "grow_capacity.hpp"

#include <cassert>
#include <limits>

namespace stc {

void SolverThreadPlan::assign(std::vector<std::uint32_t>& order,
                              const std::vector<std::array<std::uint32_t, 2>>& contact_bodies,
                              const std::vector<int>& contact_level, const std::vector<std::uint8_t>& out_of_solve,
                              const std::vector<BodyState>& bodies) {
  // Groups: the manifolds, runs of one body pair in order (a pair's contacts
  // are adjacent, as ContactBuilder emits them, and stay so in the order from
  // the ground, which is stable).
  groups_.clear();
  group_first_.clear();
  levels_.clear();  // the levels met, in that order
  // Sized by the contacts, in the tick they grow (no allocation in a later
  // tick with more manifolds or levels and no more contacts).
  for (std::vector<std::uint32_t>* v : {&group_first_, &group_order_, &block_order_, &manifold_start_, &cursor_}) {
    growCapacity(*v, order.size() + 1);
  }
  growCapacity(groups_, order.size());
  partition_.reserve(order.size(), bodies.size());
  // Shock propagation's runs: at most one a manifold, and at most kStages
  // stage starts a level from the ground (a level is at most the body count),
  // sized here and not in the tick whose contacts first reach the ground.
  growCapacity(level_runs_, order.size());
  growCapacity(level_run_block_, order.size());
  growCapacity(pass_run_block_, ContactPartition::kStages * ContactPartition::kMaxSlabs);
  growCapacity(level_stage_start_, ContactPartition::kStages * (bodies.size() + 1) + 1);
  growCapacity(manifolds_, order.size());
  growCapacity(levels_, order.size());
  for (std::size_t p = 0; p < order.size(); ++p) {
    const std::array<std::uint32_t, 2> c = contact_bodies[order[p]];
    const int level = contact_level[order[p]];
    if (levels_.empty() || levels_.back() != level) levels_.push_back(level);
    if (p > 0 && c == contact_bodies[order[p - 1]]) continue;
    SolverGroup group;
    group.a = out_of_solve[c[0]] != 0 ? SolverGroup::kStatic : c[0];
    group.b = out_of_solve[c[1]] != 0 ? SolverGroup::kStatic : c[1];
    groups_.push_back(group);
    group_first_.push_back(static_cast<std::uint32_t>(p));
  }
  group_first_.push_back(static_cast<std::uint32_t>(order.size()));
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
    for (std::uint32_t p = group_first_[g]; p < group_first_[g + 1]; ++p) block_order_.push_back(order[p]);
  }
  manifold_start_.push_back(static_cast<std::uint32_t>(block_order_.size()));
  order.swap(block_order_);

  // A pass's runs: the non-empty blocks, stage by stage.
  const std::uint32_t slabs = partition_.slabs();
  pass_runs_.clear();
  pass_run_block_.clear();
  pass_stage_start_.clear();
  for (std::uint32_t b = 0; b < block_count; ++b) {
    if (b % slabs == 0) pass_stage_start_.push_back(static_cast<std::uint32_t>(pass_runs_.size()));
    if (block_manifold_start_[b + 1] > block_manifold_start_[b]) {
      pass_runs_.push_back(ManifoldRun{block_manifold_start_[b], block_manifold_start_[b + 1]});
      pass_run_block_.push_back(b);
    }
  }
  pass_stage_start_.push_back(static_cast<std::uint32_t>(pass_runs_.size()));

  // Shock propagation's runs: within a block the manifolds are in the order
  // from the ground, so each level takes the next run of every block, stage
  // by stage. Restricted to one level, the blocks of a stage still share no
  // movable body.
  constexpr int kUnreached = std::numeric_limits<int>::max();
  level_runs_.clear();
  level_run_block_.clear();
  level_stage_start_.clear();
  cursor_.assign(block_manifold_start_.begin(), block_manifold_start_.end() - 1);
  for (const int level : levels_) {
    if (level == kUnreached) break;  // nothing static below: no shock to pass on
    for (std::uint32_t b = 0; b < block_count; ++b) {
      if (b % slabs == 0) level_stage_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
      std::uint32_t end = cursor_[b];
      while (end < block_manifold_start_[b + 1] && contact_level[order[manifold_start_[end]]] == level) ++end;
      if (end > cursor_[b]) {
        level_runs_.push_back(ManifoldRun{cursor_[b], end});
        level_run_block_.push_back(b);
      }
      cursor_[b] = end;
    }
  }
  if (!level_stage_start_.empty()) level_stage_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
  planStages(order.size(), bodies.size());
}

void SolverThreadPlan::planStages(std::size_t contacts, std::size_t body_count) {
  const std::uint32_t slabs = partition_.slabs();
  const int members = workers_ != nullptr ? workers_->threads() : 1;
  plan_members_ = (members >= 2 && slabs >= 2) ? members : 0;
  plan_runs_.clear();
  plan_start_.clear();
  plan_fused_manifolds_.clear();
  if (plan_members_ == 0) return;
  const std::size_t m_count = static_cast<std::size_t>(members);
  const auto owner = [&](std::uint32_t slab) { return static_cast<std::size_t>(slab) * m_count / slabs; };
  // -1: the block runs after the members' blocks, in its stage.
  const auto fusedMember = [&](std::uint32_t block) -> long {
    const std::uint32_t stage = block / slabs, s = block % slabs;
    if (stage == 0) return static_cast<long>(owner(s));
    if (stage == 1) return owner(s) == owner(s + 1) ? static_cast<long>(owner(s)) : -1;
    if (stage == 2) {  // after stage 1's cuts on its slabs, which must be fused too
      const std::size_t o = owner(s);
      const bool alone = owner(s - 1) == o && owner(s + 1) == o && owner(std::min(s + 2, slabs - 1)) == o;
      return alone ? static_cast<long>(o) : -1;
    }
    return -1;
  };
  const auto plan = [&](const ManifoldRun* runs, const std::uint32_t* blocks, std::size_t count) {
    const std::size_t unit = plan_start_.size();
    [[maybe_unused]] const std::size_t first_run = plan_runs_.size();
    plan_start_.resize(unit + planStride());
    plan_fused_.clear();
    std::uint32_t fused_manifolds = 0;
    for (std::size_t k = 0; k < count; ++k) {
      plan_fused_.push_back(fusedMember(blocks[k]));
      if (plan_fused_[k] >= 0) fused_manifolds += runs[k].end - runs[k].first;
    }
    for (std::size_t m = 0; m < m_count; ++m) {
      plan_start_[unit + m] = static_cast<std::uint32_t>(plan_runs_.size());
      for (std::size_t k = 0; k < count; ++k) {  // in stage order
        if (plan_fused_[k] == static_cast<long>(m)) plan_runs_.push_back(runs[k]);
      }
    }
    for (std::uint32_t stage = 1; stage < ContactPartition::kStages; ++stage) {
      plan_start_[unit + m_count + stage - 1] = static_cast<std::uint32_t>(plan_runs_.size());
      for (std::size_t k = 0; k < count; ++k) {
        if (blocks[k] / slabs == stage && plan_fused_[k] < 0) plan_runs_.push_back(runs[k]);
      }
    }
    plan_start_[unit + planStride() - 1] = static_cast<std::uint32_t>(plan_runs_.size());  // the end
    plan_fused_manifolds_.push_back(fused_manifolds);
#ifndef NDEBUG
    // Every run placed once, and no movable body in two members' blocks.
    assert(plan_runs_.size() - first_run == count);
    static thread_local std::vector<long> member_of;  // debug scratch, kept: no allocation once grown
    member_of.assign(body_count, -1);
    for (std::size_t m = 0; m < m_count; ++m) {
      for (std::uint32_t k = plan_start_[unit + m]; k < plan_start_[unit + m + 1]; ++k) {
        for (std::uint32_t g = plan_runs_[k].first; g < plan_runs_[k].end; ++g) {
          for (const std::uint32_t body : {manifolds_[g].a, manifolds_[g].b}) {
            if (body == SolverGroup::kStatic) continue;
            assert(member_of[body] < 0 || member_of[body] == static_cast<long>(m));
            member_of[body] = static_cast<long>(m);
          }
        }
      }
    }
#endif
  };
  // Sized as the runs and the level starts are (assign).
  growCapacity(plan_runs_, ContactPartition::kStages * ContactPartition::kMaxSlabs + contacts);
  growCapacity(plan_fused_, ContactPartition::kStages * ContactPartition::kMaxSlabs + contacts);
  growCapacity(plan_start_, planStride() * (body_count + 2));
  growCapacity(plan_fused_manifolds_, body_count + 2);
  plan(pass_runs_.data(), pass_run_block_.data(), pass_runs_.size());
  for (std::size_t level = 0; level < shockLevels(); ++level) {
    const std::uint32_t first = level_stage_start_[level * ContactPartition::kStages];
    const std::uint32_t end = level_stage_start_[(level + 1) * ContactPartition::kStages];
    plan(level_runs_.data() + first, level_run_block_.data() + first, end - first);
  }
}

void SolverThreadPlan::runPlan(std::size_t unit, RangeFn manifolds) const {
  const std::size_t m_count = static_cast<std::size_t>(plan_members_);
  const std::uint32_t* start = plan_start_.data() + unit * planStride();
  const std::size_t total = plan_fused_manifolds_[unit];  // the members' manifolds
  const auto member = [&](std::size_t m, std::size_t) {
    for (std::uint32_t k = start[m]; k < start[m + 1]; ++k) manifolds(plan_runs_[k].first, plan_runs_[k].end);
  };
  if (total >= task_manifolds_) {
    team_->forBlocks(m_count, member);
  } else {
    for (std::size_t m = 0; m < m_count; ++m) member(m, m + 1);
  }
  for (std::size_t stage = 0; stage + 1 < ContactPartition::kStages; ++stage) {
    runStage(plan_runs_.data() + start[m_count + stage], start[m_count + stage + 1] - start[m_count + stage], manifolds);
  }
}

void SolverThreadPlan::runStage(const ManifoldRun* runs, std::size_t count, RangeFn manifolds, std::size_t least) const {
  std::size_t total = 0;
  for (std::size_t k = 0; k < count; ++k) total += runs[k].end - runs[k].first;
  if (team_ == nullptr || count < 2 || total < (least > 0 ? least : task_manifolds_)) {
    for (std::size_t k = 0; k < count; ++k) manifolds(runs[k].first, runs[k].end);
    return;
  }
  team_->forBlocks(count, [&](std::size_t k, std::size_t) { manifolds(runs[k].first, runs[k].end); });
}

void SolverThreadPlan::forEachStage(RangeFn manifolds) const {
  if (planned()) {
    runPlan(0, manifolds);
    return;
  }
  for (std::size_t s = 0; s + 1 < pass_stage_start_.size(); ++s) {
    runStage(pass_runs_.data() + pass_stage_start_[s], pass_stage_start_[s + 1] - pass_stage_start_[s], manifolds);
  }
}

void SolverThreadPlan::forEachStageOfLevel(std::size_t level, RangeFn manifolds) const {
  if (planned()) {
    runPlan(1 + level, manifolds);
    return;
  }
  const std::size_t first = level * ContactPartition::kStages;
  for (std::size_t s = first; s < first + ContactPartition::kStages; ++s) {
    runStage(level_runs_.data() + level_stage_start_[s], level_stage_start_[s + 1] - level_stage_start_[s], manifolds);
  }
}

void SolverThreadPlan::forEachStageBatches(const std::vector<std::uint32_t>& starts, RangeFn fn) const {
  forEachStage([&](std::size_t first, std::size_t end) { fn(starts[first], starts[end]); });
}

void SolverThreadPlan::forEachStageBatchesOfLevel(std::size_t level, const std::vector<std::uint32_t>& starts,
                                                  RangeFn fn) const {
  forEachStageOfLevel(level, [&](std::size_t first, std::size_t end) { fn(starts[first], starts[end]); });
}

void SolverThreadPlan::forEachStageOfRuns(const std::vector<ManifoldRun>& runs, RangeFn fn,
                                          std::size_t per_manifold) const {
  for (std::size_t st = 0; st + 1 < pass_stage_start_.size(); ++st) {
    runStage(runs.data() + pass_stage_start_[st], pass_stage_start_[st + 1] - pass_stage_start_[st], fn,
             per_manifold * task_manifolds_);
  }
}

}  // namespace stc
