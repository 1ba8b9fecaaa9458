// Spatial partition of the solver's contact groups (contact_partition.hpp).
#include "contact_partition.hpp"

#include "grow_capacity.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

void ContactPartition::reserve(std::size_t groups, std::size_t bodies) {
  growCapacity(block_, groups);
  growCapacity(bin_, bodies);
  growCapacity(bin_weight_, kBins);
  growCapacity(slab_of_bin_, kBins);
}

void ContactPartition::assign(const std::vector<SolverGroup>& groups, const std::vector<BodyState>& bodies) {
  growCapacity(block_, groups.size());  // assign alone would reallocate to the exact count
  block_.assign(groups.size(), 0);
  slabs_ = 1;
  crossing_ = 0;
  std::uint32_t most = 1;  // the most slabs these groups may fill, a power of two
  while (2 * most <= kMaxSlabs && groups.size() >= 2 * most * kMinGroupsPerSlab) most *= 2;
  if (most == 1) return;

  // The widest axis of the movable bodies' centres.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const SolverGroup& g : groups) {
    for (const std::uint32_t body : {g.a, g.b}) {
      if (body == SolverGroup::kStatic) continue;
      lo = lo.cwiseMin(bodies[body].pose.position);
      hi = hi.cwiseMax(bodies[body].pose.position);
    }
  }
  int axis = 0;
  const double extent = (hi - lo).maxCoeff(&axis);
  if (!(extent > 0.0) || !std::isfinite(extent)) return;

  // Each body's bin along it, and the work in each bin: a group's contacts,
  // shared by its movable bodies (twice its contacts in all, so no halves).
  bin_.resize(bodies.size());
  bin_weight_.assign(kBins, 0);
  const double per_bin = kBins / extent;
  for (const SolverGroup& g : groups) {
    const std::uint32_t share = (g.a == SolverGroup::kStatic || g.b == SolverGroup::kStatic) ? 2 * g.rows : g.rows;
    for (const std::uint32_t body : {g.a, g.b}) {
      if (body == SolverGroup::kStatic) continue;
      const double at = (bodies[body].pose.position[axis] - lo[axis]) * per_bin;
      bin_[body] = std::min<std::uint32_t>(kBins - 1, static_cast<std::uint32_t>(std::max(0.0, at)));
      bin_weight_[bin_[body]] += share;
    }
  }
  for (std::uint32_t slabs = most; slabs >= 2; slabs /= 2) {
    std::size_t crossing = 0, spanning = 0;
    blockFor(slabs, groups, crossing, spanning);
    const double count = static_cast<double>(groups.size());
    if (crossing <= kMaxCrossingShare * count && spanning <= kMaxSpanningShare * count) {
      slabs_ = slabs;
      crossing_ = crossing;
      return;
    }
  }
  std::fill(block_.begin(), block_.end(), 0u);
}

void ContactPartition::blockFor(std::uint32_t slabs, const std::vector<SolverGroup>& groups, std::size_t& crossing,
                                std::size_t& spanning) {
  // Cuts between bins at equal shares of the weight: a bin goes to the slab
  // its middle falls in.
  std::uint64_t total = 0;
  for (const std::uint32_t w : bin_weight_) total += w;
  slab_of_bin_.resize(kBins);
  std::uint64_t before = 0;
  for (std::uint32_t b = 0; b < kBins; ++b) {
    const std::uint64_t middle2 = 2 * before + bin_weight_[b];  // twice the weight up to the bin's middle
    slab_of_bin_[b] = std::min<std::uint32_t>(slabs - 1, static_cast<std::uint32_t>(middle2 * slabs / (2 * total)));
    before += bin_weight_[b];
  }
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const SolverGroup& g = groups[k];
    const std::uint32_t a = slab_of_bin_[bin_[g.a != SolverGroup::kStatic ? g.a : g.b]];
    const std::uint32_t b = slab_of_bin_[bin_[g.b != SolverGroup::kStatic ? g.b : g.a]];
    const std::uint32_t low = std::min(a, b);
    const std::uint32_t high = std::max(a, b);
    if (low == high) {
      block_[k] = low;
    } else if (high == low + 1) {
      block_[k] = (1 + (low & 1u)) * slabs + low;
      ++crossing;
    } else {
      block_[k] = 3 * slabs;
      ++crossing;
      ++spanning;
    }
  }
}

}  // namespace stc
