// The contact solver's thread plan: which manifolds run together, on which
// worker, in which order. From the order up the contact graph and the
// partition's blocks (contact_partition.hpp) it puts the manifolds in block
// order, and lays out a pass's runs (one per block, stage by stage), shock
// propagation's runs (the same, level by level from the ground) and, with two
// or more workers, each member's fused blocks (planStages). The passes
// (ContactSolver) say what a range of manifolds does; the plan says where and
// when it runs. Any number of threads gives the same bits.
#pragma once

#include "contact_partition.hpp"
#include "sphere_tree_collision/body.hpp"
#include "workers.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace stc {

class SolverThreadPlan {
 public:
  // Manifolds [first, end) in block order (or, for the restitution waves,
  // rows [first, end) of a list).
  struct ManifoldRun {
    std::uint32_t first = 0, end = 0;
  };

  // Threads the passes run on (nullptr: the caller's alone). A stage of fewer
  // than `task_manifolds` manifolds runs on the calling thread.
  void setWorkers(const Workers* workers, std::size_t task_manifolds) {
    workers_ = workers;
    task_manifolds_ = std::max<std::size_t>(1, task_manifolds);
  }

  // The manifolds of `order` (contact indices up the contact graph; a body
  // pair's contacts adjacent), blocked: `order` comes back regrouped block by
  // block, manifold by manifold, and the runs and the members' plan are laid
  // out. `contact_bodies`: each contact's dense body indices; `contact_level`:
  // each contact's level from the ground; `out_of_solve`: per body, static in
  // this solve. No allocation once the capacity has grown with the contacts.
  void assign(std::vector<std::uint32_t>& order, const std::vector<std::array<std::uint32_t, 2>>& contact_bodies,
              const std::vector<int>& contact_level, const std::vector<std::uint8_t>& out_of_solve,
              const std::vector<BodyState>& bodies);

  // The manifolds in block order: manifold m's rows are [start[m], start[m + 1])
  // of `order` as assign left it; each one's movable bodies (kStatic: static).
  const std::vector<std::uint32_t>& manifoldStart() const { return manifold_start_; }
  const std::vector<SolverGroup>& manifolds() const { return manifolds_; }
  const ContactPartition& partition() const { return partition_; }
  // Block b's manifolds (b below partition().blockCount()).
  ManifoldRun block(std::uint32_t b) const { return ManifoldRun{block_manifold_start_[b], block_manifold_start_[b + 1]}; }
  // A pass's runs: the non-empty blocks, stage by stage.
  const std::vector<ManifoldRun>& passRuns() const { return pass_runs_; }
  // Shock propagation's levels from the ground (unreached rows aside).
  std::size_t shockLevels() const {
    return level_stage_start_.empty() ? 0 : (level_stage_start_.size() - 1) / ContactPartition::kStages;
  }

  // Runs `passes` on a team of the workers (awake from stage to stage), or
  // on the calling thread without workers. The forEach calls below take the
  // team's members while it runs.
  template <typename Passes>
  void onTeam(Passes&& passes) {
    if (workers_ == nullptr) {
      passes();
      return;
    }
    workers_->withTeam([&](Team& team) {
      team_ = &team;
      passes();
      team_ = nullptr;
    });
  }
  // manifolds(first, end) over every block's manifolds, stage by stage, a
  // stage's blocks on the workers, each block's manifolds by one thread.
  void forEachStage(RangeFn manifolds) const;
  // A level's manifolds stage by stage, as forEachStage (level below shockLevels()).
  void forEachStageOfLevel(std::size_t level, RangeFn manifolds) const;
  // The same over ranges of something else laid out by manifold (the wide
  // batches): fn(starts[first], starts[end]) for each run of manifolds.
  void forEachStageBatches(const std::vector<std::uint32_t>& starts, RangeFn fn) const;
  void forEachStageBatchesOfLevel(std::size_t level, const std::vector<std::uint32_t>& starts, RangeFn fn) const;
  // fn(first, end) over `runs`, one for each of passRuns() (the same blocks),
  // stage by stage, a stage on the team only when its runs hold
  // `per_manifold` times a task's manifolds or more (the restitution waves'
  // rows: per_manifold rows count as one manifold).
  void forEachStageOfRuns(const std::vector<ManifoldRun>& runs, RangeFn fn, std::size_t per_manifold) const;

 private:
  // A team's plan of one pass (unit 0) or one level (unit 1 + level): each
  // member's slabs (a contiguous range) take in one block, in stage order,
  // the blocks of stages 0-2 that touch no other member's slabs; the rest
  // (the cuts between members' slabs, the blocks after them on the same
  // slabs, stage 3) runs stage by stage after. So a pass waits for the team
  // once or twice, not three times. No two members' blocks share a movable
  // body, and each body meets its groups in the order of the four stages:
  // the result is that of forEachStage's stages, bit for bit.
  void planStages(std::size_t contacts, std::size_t body_count);
  void runPlan(std::size_t unit, RangeFn manifolds) const;
  bool planned() const { return team_ != nullptr && plan_members_ >= 2 && plan_members_ == team_->members(); }
  // The blocks runs[0, count) of one stage: on the team when there are two
  // or more and they hold `least` (task_manifolds_ when 0) or more, else in turn here.
  void runStage(const ManifoldRun* runs, std::size_t count, RangeFn manifolds, std::size_t least = 0) const;

  const Workers* workers_ = nullptr;
  std::size_t task_manifolds_ = 1;  // read only with workers_
  Team* team_ = nullptr;            // while onTeam runs
  // The manifolds in the order from the ground (groups_, each one's first
  // place in the order), their blocks, and in block order where each block's
  // manifolds start.
  ContactPartition partition_;
  std::vector<SolverGroup> groups_;
  std::vector<std::uint32_t> group_first_, group_order_, block_order_, block_manifold_start_;
  std::vector<std::uint32_t> manifold_start_;  // rows of one body pair: [start[m], start[m + 1])
  std::vector<SolverGroup> manifolds_;         // each manifold's movable bodies (kStatic: static)
  // A pass's non-empty blocks (positions in block order) and each stage's
  // first; per level from the ground and stage, its runs of manifolds, one
  // per block, and each (level, stage)'s first run.
  std::vector<ManifoldRun> pass_runs_, level_runs_;
  std::vector<std::uint32_t> pass_stage_start_, level_stage_start_, cursor_;
  std::vector<std::uint32_t> pass_run_block_, level_run_block_;  // each run's block
  // planStages: a unit's offsets into plan_runs_ (planStride() a unit): the
  // members' fused blocks, then the 3 stages left, and the end; per unit, the
  // fused blocks' manifold count. plan_fused_: each run's member (-1: left).
  std::size_t planStride() const { return static_cast<std::size_t>(plan_members_) + ContactPartition::kStages; }
  std::vector<ManifoldRun> plan_runs_;
  std::vector<std::uint32_t> plan_start_, plan_fused_manifolds_;
  std::vector<long> plan_fused_;
  int plan_members_ = 0;
  std::vector<int> levels_;
};

}  // namespace stc
