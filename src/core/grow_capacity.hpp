// Capacity that grows geometrically for buffers sized by a count that creeps up
// tick by tick (the rows of a pile that is still forming): reserving exactly
// that count reallocated, copied and page-faulted tens of megabytes every
// tick (14 % of a 10,000-cube tick); growing by half again reallocates a
// logarithmic number of times.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace stc {

template <typename T>
void growCapacity(std::vector<T>& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(std::max(n, v.capacity() + v.capacity() / 2));
}

}  // namespace stc
