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

// The same for a buffer whose elements are all written again after it is
// sized (this tick's rows, a run's queues): a growth drops the old ones
// first, so it copies nothing (copying the last tick's wide rows into their
// grown buffers took about 75 ms of one tick of a forming 10,000-cube pile).
template <typename T>
void growCapacityRewritten(std::vector<T>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  v.clear();
  growCapacity(v, n);
}

// ... and sized to n.
template <typename T>
void resizeRewritten(std::vector<T>& v, std::size_t n) {
  growCapacityRewritten(v, n);
  v.resize(n);
}

// The opposite, after a large removal (World::releaseMemory): a vector, or an
// object made of vectors, copied anew holds each at its size, not at the
// capacity it grew to; the copy replaces it.
template <typename T>
void dropSpareCapacity(T& holder) {
  holder = T(holder);
}

}  // namespace stc
