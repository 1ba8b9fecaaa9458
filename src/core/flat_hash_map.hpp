// FlatHashMap: open-addressing hash map uint64 -> uint32 (linear probing,
// backward-shift deletion). O(1) set/find/erase, flat arrays, no allocation
// until it grows. Private to the core.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace stc {
namespace detail {

class FlatHashMap {
 public:
  static constexpr std::uint32_t kMissing = 0xFFFFFFFFu;

  std::uint32_t find(std::uint64_t key) const {
    if (size_ == 0) return kMissing;
    for (std::size_t i = home(key);; i = (i + 1) & mask_) {
      if (slots_[i].key == key) return slots_[i].value;
      if (slots_[i].key == kEmpty) return kMissing;
    }
  }

  // Inserts or overwrites.
  void set(std::uint64_t key, std::uint32_t value) {
    if ((size_ + 1) * 2 > slots_.size()) grow((size_ + 1) * 2);
    std::size_t i = home(key);
    while (slots_[i].key != kEmpty && slots_[i].key != key) i = (i + 1) & mask_;
    if (slots_[i].key == kEmpty) ++size_;
    slots_[i] = {key, value};
  }

  bool erase(std::uint64_t key) {
    if (size_ == 0) return false;
    std::size_t i = home(key);
    while (slots_[i].key != key) {
      if (slots_[i].key == kEmpty) return false;
      i = (i + 1) & mask_;
    }
    // Backward shift: pull later entries of the probe run into the hole.
    std::size_t hole = i;
    for (std::size_t j = (i + 1) & mask_; slots_[j].key != kEmpty; j = (j + 1) & mask_) {
      const std::size_t h = home(slots_[j].key);
      // Entry j may move to the hole unless its home lies in (hole, j] cyclically.
      if (((j - h) & mask_) >= ((j - hole) & mask_)) {
        slots_[hole] = slots_[j];
        hole = j;
      }
    }
    slots_[hole].key = kEmpty;
    --size_;
    return true;
  }

  // Make room for n entries without growing.
  void reserve(std::size_t n) {
    if (n * 2 > slots_.size()) grow(n * 2);
  }
  std::size_t size() const { return size_; }
  // Rebuilt at the smallest table its entries fit (after many erases).
  void shrinkToFit() {
    FlatHashMap fitted;
    fitted.reserve(size_);
    for (const Slot& s : slots_)
      if (s.key != kEmpty) fitted.set(s.key, s.value);
    *this = std::move(fitted);
  }
  // Empties the map and keeps its capacity.
  void clear() {
    if (size_ == 0) return;
    for (Slot& s : slots_) s.key = kEmpty;
    size_ = 0;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  struct Slot {
    std::uint64_t key;
    std::uint32_t value;
  };

  std::size_t home(std::uint64_t key) const {
    // splitmix64 finaliser: keys may be packed pairs or patterned ids.
    key ^= key >> 30;
    key *= 0xbf58476d1ce4e5b9ull;
    key ^= key >> 27;
    key *= 0x94d049bb133111ebull;
    key ^= key >> 31;
    return static_cast<std::size_t>(key) & mask_;
  }

  void grow(std::size_t min_capacity) {
    std::size_t capacity = 16;
    while (capacity < min_capacity) capacity *= 2;
    std::vector<Slot> old(capacity, Slot{kEmpty, 0});
    old.swap(slots_);
    mask_ = capacity - 1;
    size_ = 0;
    for (const Slot& s : old)
      if (s.key != kEmpty) set(s.key, s.value);
  }

  std::vector<Slot> slots_;  // key and value together: one cache line per probe
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

}  // namespace detail
}  // namespace stc
