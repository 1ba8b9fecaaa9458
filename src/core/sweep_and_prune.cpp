// SweepAndPrune: I-COLLIDE sweep-and-prune (paper 3.2).
//
// Per axis one array of endpoints {value, slot, is_max}, kept sorted by
// insertion sort. Sorting order: value, then min before max at equal value, so
// "a.min precedes b.max" is exactly "a.min <= b.max" (Aabb::overlaps counts
// touching boxes). Insertion sort swaps every inverted pair exactly once, and a
// pair's overlap can only change when one of its min/max orders changes, so the
// swaps alone keep the overlap set exact:
//   a min moves left past a max  -> the pair may start overlapping: test 3 axes;
//   a max moves left past a min  -> the pair is now separated on this axis.
// Entities are identified by dense slots internally; ids map to slots.
#include "sphere_tree_collision/sweep_and_prune.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace stc {
namespace {

// Open-addressing hash map uint64 -> uint32 with linear probing and
// backward-shift deletion: O(1) add/remove, no allocation until it grows.
class FlatMap {
 public:
  static constexpr std::uint32_t kMissing = 0xFFFFFFFFu;

  std::uint32_t find(std::uint64_t key) const {
    if (size_ == 0) return kMissing;
    for (std::size_t i = home(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return values_[i];
      if (keys_[i] == kEmpty) return kMissing;
    }
  }

  // Inserts or overwrites.
  void set(std::uint64_t key, std::uint32_t value) {
    if ((size_ + 1) * 2 > keys_.size()) grow((size_ + 1) * 2);
    std::size_t i = home(key);
    while (keys_[i] != kEmpty && keys_[i] != key) i = (i + 1) & mask_;
    if (keys_[i] == kEmpty) ++size_;
    keys_[i] = key;
    values_[i] = value;
  }

  bool erase(std::uint64_t key) {
    if (size_ == 0) return false;
    std::size_t i = home(key);
    while (keys_[i] != key) {
      if (keys_[i] == kEmpty) return false;
      i = (i + 1) & mask_;
    }
    // Backward shift: pull later entries of the probe run into the hole.
    std::size_t hole = i;
    for (std::size_t j = (i + 1) & mask_; keys_[j] != kEmpty; j = (j + 1) & mask_) {
      const std::size_t h = home(keys_[j]);
      // Entry j may move to the hole if its home is not in (hole, j] cyclically.
      const bool home_after_hole = ((j - h) & mask_) < ((j - hole) & mask_);
      if (!home_after_hole) {
        keys_[hole] = keys_[j];
        values_[hole] = values_[j];
        hole = j;
      }
    }
    keys_[hole] = kEmpty;
    --size_;
    return true;
  }

  // Make room for n entries without growing.
  void reserve(std::size_t n) {
    if (n * 2 > keys_.size()) grow(n * 2);
  }
  std::size_t size() const { return size_; }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  std::size_t home(std::uint64_t key) const {
    // splitmix64 finaliser: pair keys are two packed slot indices.
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
    std::vector<std::uint64_t> old_keys(capacity, kEmpty);
    std::vector<std::uint32_t> old_values(capacity);
    old_keys.swap(keys_);
    old_values.swap(values_);
    mask_ = capacity - 1;
    size_ = 0;
    for (std::size_t i = 0; i < old_keys.size(); ++i)
      if (old_keys[i] != kEmpty) set(old_keys[i], old_values[i]);
  }

  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> values_;
  std::size_t mask_ = 0;
  std::size_t size_ = 0;
};

struct Endpoint {
  double value;
  std::uint32_t tag;  // slot << 1 | is_max
};

inline std::uint32_t slotOf(const Endpoint& e) { return e.tag >> 1; }
inline bool isMax(const Endpoint& e) { return (e.tag & 1u) != 0; }

// Strict order: value, then min before max at equal value.
inline bool before(const Endpoint& a, const Endpoint& b) {
  return a.value < b.value || (a.value == b.value && (a.tag & 1u) < (b.tag & 1u));
}

struct Box {
  double min[3];
  double max[3];
};

inline bool overlaps(const Box& a, const Box& b) {
  return a.min[0] <= b.max[0] && b.min[0] <= a.max[0] && a.min[1] <= b.max[1] &&
         b.min[1] <= a.max[1] && a.min[2] <= b.max[2] && b.min[2] <= a.max[2];
}

inline std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t{a} << 32) | b;
}

enum class SlotState : std::uint8_t {
  kFree,     // reusable
  kAdded,    // added since the last update(), endpoints not yet inserted
  kLive,     // endpoints in the arrays
  kRemoved,  // removed since the last update(); endpoints and pairs still there
};

Box toBox(const Aabb& a) {
  if (!a.min.allFinite() || !a.max.allFinite())
    throw InputError("box", "box corners must be finite");
  if (!(a.min.array() <= a.max.array()).all())
    throw InputError("box", "box min must be <= max on every axis");
  return Box{{a.min.x(), a.min.y(), a.min.z()}, {a.max.x(), a.max.y(), a.max.z()}};
}

}  // namespace

struct SweepAndPrune::Impl {
  std::vector<Endpoint> axis[3];
  std::vector<Box> boxes;        // by slot: the box for the next update()
  std::vector<EntityId> ids;     // by slot
  std::vector<SlotState> state;  // by slot
  std::vector<std::uint32_t> free_slots;
  std::vector<std::uint32_t> added;    // slots to insert at the next update()
  std::vector<std::uint32_t> removed;  // slots to drop at the next update()
  FlatMap slot_of_id;

  // Pair set: pairs (owned by SweepAndPrune) and pair_keys are parallel dense
  // arrays; pair_index maps a key to its index there.
  std::vector<std::uint64_t> pair_keys;
  FlatMap pair_index;

  std::vector<Endpoint> scratch;  // new endpoints of one axis, sorted before merging

  std::uint32_t slotOfId(EntityId id) const {
    const std::uint32_t slot = slot_of_id.find(id);
    if (slot == FlatMap::kMissing) throw InputError("id", "unknown entity id " + std::to_string(id));
    return slot;
  }

  void addPair(std::uint32_t a, std::uint32_t b, std::vector<BroadPair>& pairs) {
    const std::uint64_t key = pairKey(a, b);
    if (pair_index.find(key) != FlatMap::kMissing) return;
    pair_index.set(key, static_cast<std::uint32_t>(pairs.size()));
    const EntityId ia = ids[a], ib = ids[b];
    pairs.push_back(ia < ib ? BroadPair{ia, ib} : BroadPair{ib, ia});
    pair_keys.push_back(key);
  }

  void removePairAt(std::size_t index, std::vector<BroadPair>& pairs) {
    pair_index.erase(pair_keys[index]);
    const std::size_t last = pairs.size() - 1;
    if (index != last) {
      pairs[index] = pairs[last];
      pair_keys[index] = pair_keys[last];
      pair_index.set(pair_keys[index], static_cast<std::uint32_t>(index));
    }
    pairs.pop_back();
    pair_keys.pop_back();
  }

  void removePair(std::uint32_t a, std::uint32_t b, std::vector<BroadPair>& pairs) {
    const std::uint32_t index = pair_index.find(pairKey(a, b));
    if (index != FlatMap::kMissing) removePairAt(index, pairs);
  }

  // Drop the endpoints and pairs of removed slots and free the slots.
  void dropRemoved(std::vector<BroadPair>& pairs) {
    for (auto& endpoints : axis) {
      endpoints.erase(std::remove_if(endpoints.begin(), endpoints.end(),
                                     [&](const Endpoint& e) {
                                       return state[slotOf(e)] == SlotState::kRemoved;
                                     }),
                      endpoints.end());
    }
    for (std::size_t i = 0; i < pairs.size();) {
      const std::uint64_t key = pair_keys[i];
      const auto a = static_cast<std::uint32_t>(key >> 32);
      const auto b = static_cast<std::uint32_t>(key & 0xFFFFFFFFu);
      if (state[a] == SlotState::kRemoved || state[b] == SlotState::kRemoved)
        removePairAt(i, pairs);  // the last pair moved to i: look at i again
      else
        ++i;
    }
    for (std::uint32_t slot : removed) {
      state[slot] = SlotState::kFree;
      free_slots.push_back(slot);
    }
    removed.clear();
  }

  // Copy the current boxes into the endpoint values.
  void refreshValues() {
    for (int a = 0; a < 3; ++a) {
      for (Endpoint& e : axis[a]) {
        const Box& b = boxes[slotOf(e)];
        e.value = isMax(e) ? b.max[a] : b.min[a];
      }
    }
  }

  // Insertion sort of one axis; each swap of a min with a max updates the pair
  // set. Returns the number of swaps.
  std::size_t sortAxis(int a, std::vector<BroadPair>& pairs) {
    Endpoint* e = axis[a].data();
    const std::size_t n = axis[a].size();
    std::size_t swaps = 0;
    for (std::size_t i = 1; i < n; ++i) {
      const Endpoint moving = e[i];
      if (!before(moving, e[i - 1])) continue;
      std::size_t j = i;
      do {
        const Endpoint& passed = e[j - 1];
        if (!isMax(moving) && isMax(passed)) {
          // moving.min now precedes passed.max: overlap possible.
          const std::uint32_t s = slotOf(moving), t = slotOf(passed);
          if (overlaps(boxes[s], boxes[t])) addPair(s, t, pairs);
        } else if (isMax(moving) && !isMax(passed)) {
          // passed.min now follows moving.max: separated on this axis.
          removePair(slotOf(moving), slotOf(passed), pairs);
        }
        e[j] = passed;
        --j;
        ++swaps;
      } while (j > 0 && before(moving, e[j - 1]));
      e[j] = moving;
    }
    return swaps;
  }

  // Merge the endpoints of newly added slots into the sorted arrays, then find
  // each new box's overlaps with a local sweep along x.
  void insertAdded(std::vector<BroadPair>& pairs) {
    // Slots removed again before this update were freed by dropRemoved().
    added.erase(std::remove_if(added.begin(), added.end(),
                               [&](std::uint32_t s) { return state[s] != SlotState::kAdded; }),
                added.end());
    if (added.empty()) return;
    for (int a = 0; a < 3; ++a) {
      scratch.clear();
      for (std::uint32_t s : added) {
        scratch.push_back({boxes[s].min[a], s << 1});
        scratch.push_back({boxes[s].max[a], (s << 1) | 1u});
      }
      std::sort(scratch.begin(), scratch.end(), before);
      std::vector<Endpoint>& endpoints = axis[a];
      std::size_t i = endpoints.size(), j = scratch.size();
      endpoints.resize(i + j);
      for (std::size_t w = endpoints.size(); j > 0;) {
        if (i > 0 && before(scratch[j - 1], endpoints[i - 1]))
          endpoints[--w] = endpoints[--i];
        else
          endpoints[--w] = scratch[--j];
      }
    }
    for (std::uint32_t s : added) state[s] = SlotState::kLive;

    // Every box overlapping box s on x has its min in [s.min - width, s.max],
    // width = the largest x extent of any box (with a margin for rounding).
    double width = 0.0;
    for (std::size_t s = 0; s < state.size(); ++s)
      if (state[s] == SlotState::kLive) width = std::max(width, boxes[s].max[0] - boxes[s].min[0]);
    const std::vector<Endpoint>& xs = axis[0];
    for (std::uint32_t s : added) {
      const Box& box = boxes[s];
      const double from = box.min[0] - width - 1e-9 * (std::abs(box.min[0]) + width);
      auto it = std::lower_bound(xs.begin(), xs.end(), from,
                                 [](const Endpoint& e, double v) { return e.value < v; });
      for (; it != xs.end() && it->value <= box.max[0]; ++it) {
        const std::uint32_t t = slotOf(*it);
        if (isMax(*it) || t == s) continue;
        if (overlaps(box, boxes[t])) addPair(s, t, pairs);
      }
    }
    added.clear();
  }
};

SweepAndPrune::SweepAndPrune() : impl_(std::make_unique<Impl>()) {}
SweepAndPrune::~SweepAndPrune() = default;
SweepAndPrune::SweepAndPrune(SweepAndPrune&&) noexcept = default;
SweepAndPrune& SweepAndPrune::operator=(SweepAndPrune&&) noexcept = default;

void SweepAndPrune::add(EntityId id, const Aabb& box) {
  Impl& m = *impl_;
  if (m.slot_of_id.find(id) != FlatMap::kMissing)
    throw InputError("id", "entity id " + std::to_string(id) + " already added");
  const Box b = toBox(box);
  std::uint32_t slot;
  if (!m.free_slots.empty()) {
    slot = m.free_slots.back();
    m.free_slots.pop_back();
  } else {
    if (m.state.size() >= (std::size_t{1} << 31)) throw InputError("id", "too many entities");
    slot = static_cast<std::uint32_t>(m.state.size());
    m.boxes.emplace_back();
    m.ids.emplace_back();
    m.state.emplace_back();
  }
  m.boxes[slot] = b;
  m.ids[slot] = id;
  m.state[slot] = SlotState::kAdded;
  m.slot_of_id.set(id, slot);
  m.added.push_back(slot);
}

void SweepAndPrune::remove(EntityId id) {
  Impl& m = *impl_;
  const std::uint32_t slot = m.slotOfId(id);
  m.slot_of_id.erase(id);
  m.state[slot] = SlotState::kRemoved;
  m.removed.push_back(slot);
}

bool SweepAndPrune::contains(EntityId id) const {
  return impl_->slot_of_id.find(id) != FlatMap::kMissing;
}

void SweepAndPrune::setBox(EntityId id, const Aabb& box) {
  Impl& m = *impl_;
  const std::uint32_t slot = m.slotOfId(id);
  m.boxes[slot] = toBox(box);
}

void SweepAndPrune::update() {
  Impl& m = *impl_;
  if (!m.removed.empty()) m.dropRemoved(pairs_);
  m.refreshValues();
  last_swaps_ = 0;
  for (int a = 0; a < 3; ++a) last_swaps_ += m.sortAxis(a, pairs_);
  if (!m.added.empty()) {
    const std::size_t entities = m.slot_of_id.size();
    // Room for a typical pair count, so steady-state ticks do not allocate.
    if (pairs_.capacity() < 2 * entities) {
      pairs_.reserve(2 * entities);
      m.pair_keys.reserve(2 * entities);
    }
    m.pair_index.reserve(2 * entities);
    m.insertAdded(pairs_);
  }
}

std::size_t SweepAndPrune::size() const { return impl_->slot_of_id.size(); }

}  // namespace stc
