// The solver's rows in colour order (contact_colouring.hpp) and the loop that
// runs a pass over them colour by colour, each colour's groups in parallel.
#include "sphere_tree_collision/contact_solver.hpp"

namespace stc {
namespace {

// Body-pair groups a task of a colour takes at least (a row is ~50 ns a pass):
// a smaller colour is solved on the calling thread.
constexpr std::size_t kGroupsPerTask = 32;

}  // namespace

void ContactSolver::colourRows(std::size_t body_count) {
  // Groups: runs of rows of one body pair (a pair's contacts are adjacent,
  // and stay so in the order from the ground, which is stable).
  groups_.clear();
  group_of_row_.clear();  // here: each group's first row, in the order from the ground
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
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
  by_level_.resize(rows_.size());
  sorted_rows_.clear();
  for (std::size_t pos = 0; pos < group_order_.size(); ++pos) {
    const std::uint32_t g = group_order_[pos];
    group_row_start_[pos] = static_cast<std::uint32_t>(sorted_rows_.size());
    for (std::uint32_t r = group_of_row_[g]; r < group_of_row_[g + 1]; ++r) {
      by_level_[r] = static_cast<std::uint32_t>(sorted_rows_.size());
      sorted_rows_.push_back(rows_[r]);
    }
  }
  group_row_start_[groups_.size()] = static_cast<std::uint32_t>(sorted_rows_.size());
  rows_.swap(sorted_rows_);
}

void ContactSolver::forEachColour(RangeFn rows) {
  for (std::size_t c = 0; c + 1 < colour_group_start_.size(); ++c) {
    const std::uint32_t first = colour_group_start_[c];
    const std::uint32_t groups = colour_group_start_[c + 1] - first;
    forEachIndex(workers_, groups, kGroupsPerTask, [&](std::size_t begin, std::size_t end) {
      rows(group_row_start_[first + begin], group_row_start_[first + end]);
    });
  }
}

}  // namespace stc
