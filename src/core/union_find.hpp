// Union-find over dense body indices, as the islands of one tick need it:
// path halving, and the lower root wins a union (so an island's root is its
// lowest index, whatever the order of the unions). Islands (sleep) and
// IslandLevels (held islands) both group bodies this way.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace stc {

inline std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];  // path halving
    i = parent[i];
  }
  return i;
}

inline void uniteRoots(std::vector<std::uint32_t>& parent, std::uint32_t a, std::uint32_t b) {
  const std::uint32_t ra = findRoot(parent, a), rb = findRoot(parent, b);
  if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
}

}  // namespace stc
