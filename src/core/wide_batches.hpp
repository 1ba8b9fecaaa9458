// The layout of the solver's 4-wide passes (ResponseOptions::wide_passes):
// a block's manifolds (solver_thread_plan.hpp) in batches of up to kLanes
// that share no movable body, each manifold in a batch after those of the
// block's earlier manifolds on its bodies, and room for each batch's rows
// side by side, one lane a manifold. Every body so meets its manifolds in the
// block's order, and the wide passes (contact_solver_wide.cpp) give the
// one-at-a-time passes' result bit for bit. This part decides which
// manifolds share a batch and holds the wide rows; ContactSolver packs its
// rows into them and runs the passes.
#pragma once

#include "contact_partition.hpp"
#include "grow_capacity.hpp"
#include "solver_thread_plan.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace stc {

class WideBatches {
 public:
  static constexpr std::uint32_t kLanes = 4;
  // One row of each lane's manifold (a lane without one here is left alone).
  // What a velocity pass streams: t2 is n x t1 again (tangentBasis), and
  // shock propagation's masses are in a ShockMass of the same place.
  struct alignas(32) Row {
    double ra[3][kLanes], rb[3][kLanes], n[3][kLanes], t1[3][kLanes];
    double ang_a[3][3][kLanes], ang_b[3][3][kLanes];  // [direction][axis][lane]
    double inv_ma[kLanes], inv_mb[kLanes], mass[3][kLanes];
    double friction[kLanes], speculative[kLanes], bounce_impulse[kLanes];
    double lambda[3][kLanes];
  };
  struct alignas(32) ShockMass {
    double mass[3][kLanes];
  };
  // The same for the split-impulse passes by translation (the rows' push terms).
  struct alignas(32) Push {
    double n[3][kLanes];
    double inv_ma[kLanes], inv_mb[kLanes], push[kLanes], mass[kLanes], shock_mass[kLanes], lambda[kLanes];
    long long pull[kLanes];  // all ones: may pull (bounced across a gap), else clamped at 0
  };
  // Each lane's rolling resistance (ContactSolver::Rolling), one a batch:
  // matrices [row][column][lane]; per_normal 0 in a lane without it.
  struct alignas(32) Rolling {
    double mass[3][3][kLanes], inv_ia[3][3][kLanes], inv_ib[3][3][kLanes];
    double per_normal[kLanes];
    double lambda[3][kLanes];
  };
  struct Batch {
    std::uint32_t first_row = 0, rows = 0;  // its wide rows: as many as its largest manifold's
    std::uint32_t lanes = 0;
    std::uint32_t manifold[kLanes] = {};
    std::uint32_t manifold_rows[kLanes] = {};
    std::uint32_t body_a[kLanes] = {}, body_b[kLanes] = {};  // dense indices (a static one is read, never written)
    bool write_a[kLanes] = {}, write_b[kLanes] = {};
    bool move_a[kLanes] = {}, move_b[kLanes] = {};  // shock propagation: not held
  };
  // What the batching reads of one manifold (of its first row).
  struct ManifoldFacts {
    int level = 0;  // from the ground: each level's run of a block is batched on its own
    std::uint32_t body_a = 0, body_b = 0;
    bool move_a = true, move_b = true;
  };

  // Batches the plan's manifolds, `facts(m)` giving manifold m's
  // ManifoldFacts; `rows` of them in all, on `bodies` bodies. No allocation
  // in a later tick that batches differently with no more rows.
  template <typename FactsOf>
  void assign(const SolverThreadPlan& plan, std::size_t rows, std::size_t bodies, FactsOf&& facts);

  const std::vector<Batch>& batches() const { return batches_; }
  // By manifold: where a block or a level's run of it starts in batches()
  // (for SolverThreadPlan::forEachStageBatches).
  const std::vector<std::uint32_t>& starts() const { return batch_start_; }
  std::vector<Row>& rows() { return rows_; }
  std::vector<ShockMass>& shockMass() { return shock_mass_; }
  std::vector<Push>& push() { return push_; }
  std::vector<Rolling>& rolling() { return rolling_; }  // by batch

 private:
  std::vector<Batch> batches_;
  std::vector<Row> rows_;
  std::vector<ShockMass> shock_mass_;
  std::vector<Push> push_;
  std::vector<Rolling> rolling_;
  std::vector<std::uint32_t> batch_start_;
  std::vector<std::uint32_t> body_batch_;  // assign: a body's last batch + 1
};

template <typename FactsOf>
void WideBatches::assign(const SolverThreadPlan& plan, std::size_t rows, std::size_t bodies, FactsOf&& facts) {
  // Sized by the rows, in the tick they grow: a batch holds at least one
  // manifold, and its wide rows are at most its manifolds' rows. The batches
  // are cleared first: a growth copies nothing of the last tick's.
  batches_.clear();
  growCapacityRewritten(batch_start_, rows + 1);
  growCapacityRewritten(batches_, rows);
  growCapacityRewritten(rows_, rows);
  growCapacityRewritten(shock_mass_, rows);
  growCapacityRewritten(push_, rows);
  growCapacityRewritten(rolling_, rows);
  const std::vector<std::uint32_t>& manifold_start = plan.manifoldStart();
  const std::vector<SolverGroup>& manifolds = plan.manifolds();
  batch_start_.assign(manifolds.size() + 1, 0);
  body_batch_.assign(bodies, 0);
  // A block's manifolds are in the order from the ground; each level's run
  // of them (shock propagation's unit, SolverThreadPlan::assign) is batched on its own.
  const std::uint32_t block_count = plan.partition().blockCount();
  for (std::uint32_t block = 0; block < block_count; ++block) {
    const SolverThreadPlan::ManifoldRun block_manifolds = plan.block(block);
    const std::uint32_t end_manifold = block_manifolds.end;
    std::uint32_t open = 0;  // the run's batches before it are full
    for (std::uint32_t m = block_manifolds.first; m < end_manifold; ++m) {
      if (m == block_manifolds.first || facts(m).level != facts(m - 1).level) {
        open = static_cast<std::uint32_t>(batches_.size());
        batch_start_[m] = open;
      }
      const SolverGroup& group = manifolds[m];
      // After the batches of the run's manifolds so far on either body
      // (body_batch_ from an earlier run is at most the run's first).
      std::uint32_t k = open;
      if (group.a != SolverGroup::kStatic) k = std::max(k, body_batch_[group.a]);
      if (group.b != SolverGroup::kStatic) k = std::max(k, body_batch_[group.b]);
      while (k < batches_.size() && batches_[k].lanes == kLanes) ++k;
      if (k == batches_.size()) batches_.emplace_back();
      Batch& batch = batches_[k];
      batch.manifold[batch.lanes] = m;
      batch.manifold_rows[batch.lanes] = manifold_start[m + 1] - manifold_start[m];
      batch.rows = std::max(batch.rows, batch.manifold_rows[batch.lanes]);
      ++batch.lanes;
      if (group.a != SolverGroup::kStatic) body_batch_[group.a] = k + 1;
      if (group.b != SolverGroup::kStatic) body_batch_[group.b] = k + 1;
      while (open < batches_.size() && batches_[open].lanes == kLanes) ++open;
    }
    batch_start_[end_manifold] = static_cast<std::uint32_t>(batches_.size());
  }
  std::uint32_t wide_rows = 0;
  for (Batch& batch : batches_) {
    batch.first_row = wide_rows;
    wide_rows += batch.rows;
    for (std::uint32_t l = 0; l < batch.lanes; ++l) {
      const std::uint32_t m = batch.manifold[l];
      const ManifoldFacts manifold = facts(m);
      batch.body_a[l] = manifold.body_a;
      batch.body_b[l] = manifold.body_b;
      batch.write_a[l] = manifolds[m].a != SolverGroup::kStatic;
      batch.write_b[l] = manifolds[m].b != SolverGroup::kStatic;
      batch.move_a[l] = manifold.move_a;
      batch.move_b[l] = manifold.move_b;
    }
  }
  rows_.resize(wide_rows);
  shock_mass_.resize(wide_rows);
  push_.resize(wide_rows);
  rolling_.resize(batches_.size());
}

}  // namespace stc
