// The solver's manifolds in colour order (contact_colouring.hpp) and the loop
// that runs a pass over them colour by colour, each colour's manifolds in
// parallel.
#include "sphere_tree_collision/contact_solver.hpp"

#include <limits>

namespace stc {

void ContactSolver::colourManifolds(const std::vector<BodyState>& bodies, const std::vector<Contact>& contacts) {
  // Groups: the manifolds, runs of one body pair in order_ (a pair's contacts
  // are adjacent, as ContactBuilder emits them, and stay so in the order from
  // the ground, which is stable).
  groups_.clear();
  group_first_.clear();
  levels_.clear();  // the levels met, in that order
  // Sized by the contacts, in the tick they grow (no allocation in a later
  // tick with more manifolds or levels and no more contacts).
  // (Colours are at most the manifolds, manifolds at most the contacts.)
  for (std::vector<std::uint32_t>* v : {&group_first_, &group_order_, &colour_order_, &manifold_start_,
                                        &colour_manifold_start_, &cursor_}) {
    v->reserve(order_.size() + 1);
  }
  colouring_.reserve(order_.size());
  groups_.reserve(order_.size());
  manifolds_.reserve(order_.size());
  levels_.reserve(order_.size());
  level_runs_.reserve(order_.size());
  level_segment_start_.reserve(order_.size() + 1);
  for (std::size_t p = 0; p < order_.size(); ++p) {
    const Contact& c = contacts[order_[p]];
    const int level = levelOf(c);
    if (levels_.empty() || levels_.back() != level) levels_.push_back(level);
    if (p > 0) {
      const Contact& previous = contacts[order_[p - 1]];
      if (c.index_a == previous.index_a && c.index_b == previous.index_b) continue;
    }
    ColourGroup group;
    group.a = bodies[c.index_a].is_static ? ColourGroup::kStatic : c.index_a;
    group.b = bodies[c.index_b].is_static ? ColourGroup::kStatic : c.index_b;
    groups_.push_back(group);
    group_first_.push_back(static_cast<std::uint32_t>(p));
  }
  group_first_.push_back(static_cast<std::uint32_t>(order_.size()));
  colouring_.assign(groups_, bodies.size());

  // Manifolds by colour, stable (counting sort), then their contacts in that order.
  const std::vector<std::uint32_t>& colour = colouring_.colours();
  colour_manifold_start_.assign(colouring_.colourCount() + 1, 0);
  for (std::size_t g = 0; g < groups_.size(); ++g) ++colour_manifold_start_[colour[g] + 1];
  for (std::size_t c = 1; c < colour_manifold_start_.size(); ++c) {
    colour_manifold_start_[c] += colour_manifold_start_[c - 1];
  }
  cursor_.assign(colour_manifold_start_.begin(), colour_manifold_start_.end() - 1);  // fill positions
  group_order_.resize(groups_.size());
  for (std::uint32_t g = 0; g < groups_.size(); ++g) group_order_[cursor_[colour[g]]++] = g;
  colour_order_.clear();
  manifold_start_.clear();
  manifolds_.clear();
  for (const std::uint32_t g : group_order_) {
    manifold_start_.push_back(static_cast<std::uint32_t>(colour_order_.size()));
    manifolds_.push_back(groups_[g]);
    for (std::uint32_t p = group_first_[g]; p < group_first_[g + 1]; ++p) colour_order_.push_back(order_[p]);
  }
  manifold_start_.push_back(static_cast<std::uint32_t>(colour_order_.size()));
  order_.swap(colour_order_);

  // Shock propagation's runs: within a colour the manifolds are in the order
  // from the ground, so each level takes the next run of every colour.
  // Restricted to one level, colour order still meets each body's rows in
  // the serial order: a level colour by colour gives the serial bits too.
  constexpr int kUnreached = std::numeric_limits<int>::max();
  level_runs_.clear();
  level_segment_start_.clear();
  cursor_.assign(colour_manifold_start_.begin(), colour_manifold_start_.end() - 1);
  for (const int level : levels_) {
    if (level == kUnreached) break;  // nothing static below: no shock to pass on
    level_segment_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
    for (std::size_t c = 0; c < cursor_.size(); ++c) {
      std::uint32_t end = cursor_[c];
      while (end < colour_manifold_start_[c + 1] && levelOf(contacts[order_[manifold_start_[end]]]) == level) ++end;
      if (end > cursor_[c]) level_runs_.push_back(ManifoldRun{cursor_[c], end});
      cursor_[c] = end;
    }
  }
  if (!level_segment_start_.empty()) level_segment_start_.push_back(static_cast<std::uint32_t>(level_runs_.size()));
}

void ContactSolver::forEachManifoldRun(std::uint32_t first, std::uint32_t end, RangeFn manifolds) const {
  forEachIndex(workers_, end - first, task_manifolds_,
               [&](std::size_t begin, std::size_t stop) { manifolds(first + begin, first + stop); });
}

void ContactSolver::forEachColour(RangeFn manifolds) {
  for (std::size_t c = 0; c + 1 < colour_manifold_start_.size(); ++c) {
    forEachManifoldRun(colour_manifold_start_[c], colour_manifold_start_[c + 1], manifolds);
  }
}

void ContactSolver::forEachColourOfLevel(std::size_t level, RangeFn manifolds) {
  for (std::uint32_t k = level_segment_start_[level]; k < level_segment_start_[level + 1]; ++k) {
    forEachManifoldRun(level_runs_[k].first, level_runs_[k].end, manifolds);
  }
}

}  // namespace stc
