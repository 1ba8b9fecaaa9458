// The solver's rows in colour order (contact_colouring.hpp) and the loop that
// runs a pass over them colour by colour, each colour's groups in parallel.
#include "sphere_tree_collision/contact_solver.hpp"

#include <limits>

namespace stc {
namespace {

// Body-pair groups a task of a colour takes at least (a row is ~50 ns a pass):
// a smaller colour is solved on the calling thread.
constexpr std::size_t kGroupsPerTask = 128;

}  // namespace

void ContactSolver::colourRows(std::size_t body_count) {
  // Groups: runs of rows of one body pair (a pair's contacts are adjacent,
  // and stay so in the order from the ground, which is stable).
  groups_.clear();
  group_of_row_.clear();  // here: each group's first row, in the order from the ground
  levels_.clear();        // the levels met, in that order
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    if (levels_.empty() || levels_.back() != row.level) levels_.push_back(row.level);
    if (r > 0 && row.a == rows_[r - 1].a && row.b == rows_[r - 1].b) continue;
    ColourGroup group;
    group.a = row.static_a ? ColourGroup::kStatic : row.a;
    group.b = row.static_b ? ColourGroup::kStatic : row.b;
    groups_.push_back(group);
    group_of_row_.push_back(static_cast<std::uint32_t>(r));
  }
  group_of_row_.push_back(static_cast<std::uint32_t>(rows_.size()));
  colouring_.assign(groups_, body_count);

  // Groups by colour, stable (counting sort), then their rows in that order.
  const std::vector<std::uint32_t>& colour = colouring_.colours();
  colour_group_start_.assign(colouring_.colourCount() + 1, 0);
  for (std::size_t g = 0; g < groups_.size(); ++g) ++colour_group_start_[colour[g] + 1];
  for (std::size_t c = 1; c < colour_group_start_.size(); ++c) colour_group_start_[c] += colour_group_start_[c - 1];
  group_order_.resize(groups_.size());
  group_row_start_.assign(colour_group_start_.begin(), colour_group_start_.end() - 1);  // fill positions
  for (std::uint32_t g = 0; g < groups_.size(); ++g) group_order_[group_row_start_[colour[g]]++] = g;
  group_row_start_.resize(groups_.size() + 1);
  sorted_rows_.clear();
  for (std::size_t pos = 0; pos < group_order_.size(); ++pos) {
    const std::uint32_t g = group_order_[pos];
    group_row_start_[pos] = static_cast<std::uint32_t>(sorted_rows_.size());
    for (std::uint32_t r = group_of_row_[g]; r < group_of_row_[g + 1]; ++r) sorted_rows_.push_back(rows_[r]);
  }
  group_row_start_[groups_.size()] = static_cast<std::uint32_t>(sorted_rows_.size());
  rows_.swap(sorted_rows_);

  // Shock propagation's runs: within a colour the groups are in the order
  // from the ground, so each level takes the next run of every colour.
  // Restricted to one level, colour order still meets each body's rows in
  // the serial order: a level colour by colour gives the serial bits too.
  constexpr int kUnreached = std::numeric_limits<int>::max();
  level_runs_.clear();
  level_segment_start_.clear();
  cursor_.assign(colour_group_start_.begin(), colour_group_start_.end() - 1);
  for (const int level : levels_) {
    if (level == kUnreached) break;  // nothing static below: no shock to pass on
    level_segment_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
    for (std::size_t c = 0; c < cursor_.size(); ++c) {
      std::uint32_t end = cursor_[c];
      while (end < colour_group_start_[c + 1] && rows_[group_row_start_[end]].level == level) ++end;
      if (end > cursor_[c]) level_runs_.push_back(GroupRun{cursor_[c], end});
      cursor_[c] = end;
    }
  }
  if (!level_segment_start_.empty()) level_segment_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
}

void ContactSolver::forEachGroupRun(std::uint32_t first, std::uint32_t end, RangeFn rows) const {
  forEachIndex(workers_, end - first, kGroupsPerTask, [&](std::size_t begin, std::size_t stop) {
    rows(group_row_start_[first + begin], group_row_start_[first + stop]);
  });
}

void ContactSolver::forEachColour(RangeFn rows) {
  for (std::size_t c = 0; c + 1 < colour_group_start_.size(); ++c) {
    forEachGroupRun(colour_group_start_[c], colour_group_start_[c + 1], rows);
  }
}

void ContactSolver::forEachColourOfLevel(std::size_t level, RangeFn rows) {
  for (std::uint32_t k = level_segment_start_[level]; k < level_segment_start_[level + 1]; ++k) {
    forEachGroupRun(level_runs_[k].first, level_runs_[k].end, rows);
  }
}

}  // namespace stc
