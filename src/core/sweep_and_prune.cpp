// SweepAndPrune: I-COLLIDE sweep-and-prune (paper 3.2).
//
// Per axis one array of endpoints {value, slot, is_max}, kept sorted by
// insertion sort. Sorting order: value, then min before max at equal value, so
// "a.min precedes b.max" is exactly "a.min <= b.max" (Aabb::overlaps counts
// touching boxes). Insertion sort swaps every inverted pair exactly once, and a
// pair's overlap can only change when one of its min/max orders changes, so the
// swaps alone keep the overlap set exact:
//   a min moves left past a max  -> the pair may start overlapping (join);
//   a max moves left past a min  -> the pair is now separated on this axis.
// Most such swaps are between boxes far apart on the other axes, so two filters
// that need no random memory access drop them during the sort:
//   join:     each endpoint carries its box's ranges on the two other axes,
//             quantised monotonically to 8 bits (conservative): no overlap
//             there, no event;
//   separate: each slot has a 64-bit Bloom mask of its current partners' slots:
//             bit clear, the pair is not in the set, nothing to remove.
// Surviving events are applied after the three sorts. Entities are dense slots
// inside; ids map to slots.
#include "sphere_tree_collision/sweep_and_prune.hpp"

#include "flat_hash_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace stc {
namespace {

using detail::FlatHashMap;

struct Endpoint {
  double value;
  std::uint32_t tag;    // slot << 1 | is_max
  std::uint32_t others;  // the box's quantised ranges on the other two axes
};

inline std::uint32_t slotOf(const Endpoint& e) { return e.tag >> 1; }
inline std::uint32_t isMax(const Endpoint& e) { return e.tag & 1u; }

// Strict order: value, then min before max at equal value.
inline bool before(const Endpoint& a, const Endpoint& b) {
  return a.value < b.value || (a.value == b.value && isMax(a) < isMax(b));
}

// Two quantised ranges packed per word, byte by byte: lo1, hi1, lo2, hi2.
// Both overlap (necessary for the exact ranges to overlap).
inline std::uint32_t rangesMayOverlap(std::uint32_t a, std::uint32_t b) {
  const auto byte = [](std::uint32_t w, int k) { return (w >> (8 * k)) & 0xFFu; };
  return static_cast<std::uint32_t>(byte(a, 0) <= byte(b, 1)) &
         static_cast<std::uint32_t>(byte(b, 0) <= byte(a, 1)) &
         static_cast<std::uint32_t>(byte(a, 2) <= byte(b, 3)) &
         static_cast<std::uint32_t>(byte(b, 2) <= byte(a, 3));
}

// A box's extent on one axis, stored per axis so that sorting one axis reads
// one compact array. others: the quantised ranges on the other two axes.
struct alignas(32) Span {
  double min;
  double max;
  std::uint32_t others;
};

// Monotone map of a coordinate to 0..255: a <= b implies q(a) <= q(b), so
// quantised ranges of overlapping intervals overlap.
struct Quantiser {
  double origin = 0.0;
  double scale = 0.0;
  std::uint32_t operator()(double v) const {
    const double x = (v - origin) * scale;  // NaN only when scale is 0: maps to 0 like all
    return x > 0.0 ? static_cast<std::uint32_t>(std::min(x, 255.0)) : 0u;
  }
};

inline std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t{a} << 32) | b;
}

inline std::uint64_t bloomBit(std::uint32_t slot) { return std::uint64_t{1} << (slot & 63u); }

enum class SlotState : std::uint8_t {
  kFree,     // reusable
  kAdded,    // added since the last update(), endpoints not yet inserted
  kLive,     // endpoints in the arrays
  kRemoved,  // removed since the last update(); endpoints and pairs still there
};

void checkBox(const Aabb& a) {
  if (!a.min.allFinite() || !a.max.allFinite())
    throw InputError("box", "box corners must be finite");
  if (!(a.min.array() <= a.max.array()).all())
    throw InputError("box", "box min must be <= max on every axis");
}

}  // namespace

struct SweepAndPrune::Impl {
  std::vector<Endpoint> axis[3];
  std::vector<Span> spans[3];    // by slot, per axis: the box for the next update()
  std::vector<EntityId> ids;     // by slot
  std::vector<SlotState> state;  // by slot
  std::vector<std::uint64_t> partner_bloom;  // by slot, rebuilt each update()
  std::vector<std::uint32_t> free_slots;
  std::vector<std::uint32_t> added;    // slots to insert at the next update()
  std::vector<std::uint32_t> removed;  // slots to drop at the next update()
  FlatHashMap slot_of_id;
  std::uint32_t last_set = ~0u;  // slot of the last setBox: callers often go in add order

  // Pair set: pairs (owned by SweepAndPrune) and pair_keys are parallel dense
  // arrays; pair_index maps a key to its index there.
  std::vector<std::uint64_t> pair_keys;
  FlatHashMap pair_index;

  // Swaps that may change the pair set: moving slot << 32 | kind | passed slot;
  // events[0, event_count) are this update's, the rest is room.
  static constexpr std::uint64_t kSeparate = 1u << 31;
  static constexpr std::size_t kLookAhead = 8;
  std::vector<std::uint64_t> events;
  std::size_t event_count = 0;
  std::vector<Endpoint> scratch;  // new endpoints of one axis, sorted before merging

  std::uint32_t slotOfId(EntityId id) const {
    const std::uint32_t slot = slot_of_id.find(id);
    if (slot == FlatHashMap::kMissing) throw InputError("id", "unknown entity id " + std::to_string(id));
    return slot;
  }

  bool inUse(std::uint32_t slot) const {
    return state[slot] == SlotState::kLive || state[slot] == SlotState::kAdded;
  }

  void setSpans(std::uint32_t slot, const Aabb& box) {
    for (int a = 0; a < 3; ++a) {
      spans[a][slot].min = box.min[a];
      spans[a][slot].max = box.max[a];
    }
  }

  bool overlaps(std::uint32_t s, std::uint32_t t) const {
    for (int a = 0; a < 3; ++a) {
      const Span& p = spans[a][s];
      const Span& q = spans[a][t];
      if (!(p.min <= q.max && q.min <= p.max)) return false;
    }
    return true;
  }

  void addPair(std::uint32_t a, std::uint32_t b, std::vector<BroadPair>& pairs) {
    const std::uint64_t key = pairKey(a, b);
    if (pair_index.find(key) != FlatHashMap::kMissing) return;
    pair_index.set(key, static_cast<std::uint32_t>(pairs.size()));
    const EntityId ia = ids[a], ib = ids[b];
    pairs.push_back(ia < ib ? BroadPair{ia, ib} : BroadPair{ib, ia});
    pair_keys.push_back(key);
    partner_bloom[a] |= bloomBit(b);
    partner_bloom[b] |= bloomBit(a);
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
    if (index != FlatHashMap::kMissing) removePairAt(index, pairs);
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

  // Bloom masks of the current pair set (removals leave stale bits: rebuild).
  void rebuildBlooms() {
    std::fill(partner_bloom.begin(), partner_bloom.end(), 0);
    for (const std::uint64_t key : pair_keys) {
      const auto a = static_cast<std::uint32_t>(key >> 32);
      const auto b = static_cast<std::uint32_t>(key & 0xFFFFFFFFu);
      partner_bloom[a] |= bloomBit(b);
      partner_bloom[b] |= bloomBit(a);
    }
  }

  // Quantise every box over the bounds of all boxes into the others field of
  // its spans (the endpoints copy it in sortAxis).
  void quantiseRanges() {
    const std::size_t slots = state.size();
    Quantiser q[3];
    for (int a = 0; a < 3; ++a) {
      double lo = INFINITY, hi = -INFINITY;
      for (std::size_t s = 0; s < slots; ++s) {
        if (!inUse(static_cast<std::uint32_t>(s))) continue;
        lo = std::min(lo, spans[a][s].min);
        hi = std::max(hi, spans[a][s].max);
      }
      q[a].origin = lo <= hi ? lo : 0.0;
      const double extent = hi - lo;
      // Zero or overflowing extent: scale 0 maps all to 0, still conservative.
      q[a].scale = extent > 0.0 && std::isfinite(extent) ? 255.0 / extent : 0.0;
    }
    for (std::size_t s = 0; s < slots; ++s) {
      std::uint32_t range[3];
      for (int a = 0; a < 3; ++a) range[a] = q[a](spans[a][s].min) | (q[a](spans[a][s].max) << 8);
      for (int a = 0; a < 3; ++a) spans[a][s].others = range[(a + 1) % 3] | (range[(a + 2) % 3] << 16);
    }
  }

  // Refresh and insertion-sort one axis, recording the min/max swaps that
  // pass the filters as events. The inner loop is branch-free but for its exit: an
  // event is always written, the cursor advanced only when it counts.
  // Returns the number of swaps.
  std::size_t sortAxis(int a) {
    Endpoint* e = axis[a].data();
    const std::size_t n = axis[a].size();
    const std::uint64_t* bloom = partner_bloom.data();
    const Span* span = spans[a].data();
    std::size_t swaps = 0;
    for (std::size_t i = 0; i < n; ++i) {
      // Copy the new box into e[i] (untouched so far: the sort has only
      // shifted e[0, i)), fetching the span needed a few steps ahead.
      if (i + kLookAhead < n) __builtin_prefetch(&span[slotOf(e[i + kLookAhead])]);
      const Span& sp = span[slotOf(e[i])];
      e[i].value = isMax(e[i]) ? sp.max : sp.min;
      e[i].others = sp.others;
      const Endpoint moving = e[i];
      if (i == 0 || !before(moving, e[i - 1])) continue;
      // Room for one event per swap this endpoint can make.
      if (events.size() - event_count < i) events.resize(2 * events.size() + i);
      std::uint64_t* out = events.data() + event_count;
      const std::uint32_t moving_max = isMax(moving);
      const std::uint64_t head = (std::uint64_t{slotOf(moving)} << 32) | (moving_max ? kSeparate : 0);
      // A min passing a max may start an overlap: filter on the other axes.
      // A max passing a min ends one if there was one: filter on the Bloom mask.
      const std::uint64_t partners = bloom[slotOf(moving)];
      const std::uint32_t join = moving_max ^ 1u;
      std::size_t j = i;
      do {
        const Endpoint passed = e[j - 1];
        const std::uint32_t t = slotOf(passed);
        *out = head | t;
        const std::uint32_t partner = static_cast<std::uint32_t>(partners >> (t & 63u)) & 1u;
        const std::uint32_t near = rangesMayOverlap(moving.others, passed.others);
        out += (moving_max ^ isMax(passed)) & ((join & near) | (moving_max & partner));
        e[j] = passed;
        --j;
      } while (j > 0 && before(moving, e[j - 1]));
      event_count = static_cast<std::size_t>(out - events.data());
      swaps += i - j;
      e[j] = moving;
    }
    return swaps;
  }

  // Apply the events of all three axes. Order does not matter: a join adds a
  // pair only if the boxes overlap on every axis now, and a pair with a
  // separate event does not.
  void applyEvents(std::vector<BroadPair>& pairs) {
    for (std::size_t k = 0; k < event_count; ++k) {
      const std::uint64_t ev = events[k];
      const auto s = static_cast<std::uint32_t>(ev >> 32);
      const auto t = static_cast<std::uint32_t>(ev & ~kSeparate & 0xFFFFFFFFu);
      if (ev & kSeparate)
        removePair(s, t, pairs);
      else if (overlaps(s, t))
        addPair(s, t, pairs);
    }
    event_count = 0;
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
      const std::vector<Span>& span = spans[a];
      scratch.clear();
      for (std::uint32_t s : added) {
        scratch.push_back({span[s].min, s << 1, span[s].others});
        scratch.push_back({span[s].max, (s << 1) | 1u, span[s].others});
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
    const std::vector<Span>& xspan = spans[0];
    double width = 0.0;
    for (std::size_t s = 0; s < state.size(); ++s)
      if (state[s] == SlotState::kLive) width = std::max(width, xspan[s].max - xspan[s].min);
    const std::vector<Endpoint>& xs = axis[0];
    // In x order, consecutive windows overlap and stay in cache.
    std::sort(added.begin(), added.end(),
              [&](std::uint32_t s, std::uint32_t t) { return xspan[s].min < xspan[t].min; });
    for (std::uint32_t s : added) {
      const Span& x = xspan[s];
      const double from = x.min - width - 1e-9 * (std::abs(x.min) + width);
      auto it = std::lower_bound(xs.begin(), xs.end(), from,
                                 [](const Endpoint& e, double v) { return e.value < v; });
      for (; it != xs.end() && it->value <= x.max; ++it) {
        if (isMax(*it) || !rangesMayOverlap(x.others, it->others)) continue;
        const std::uint32_t t = slotOf(*it);
        if (t != s && overlaps(s, t)) addPair(s, t, pairs);
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
  if (m.slot_of_id.find(id) != FlatHashMap::kMissing)
    throw InputError("id", "entity id " + std::to_string(id) + " already added");
  checkBox(box);
  std::uint32_t slot;
  if (!m.free_slots.empty()) {
    slot = m.free_slots.back();
    m.free_slots.pop_back();
  } else {
    if (m.state.size() >= (std::size_t{1} << 31)) throw InputError("id", "too many entities");
    slot = static_cast<std::uint32_t>(m.state.size());
    for (auto& span : m.spans) span.emplace_back();
    m.ids.emplace_back();
    m.state.emplace_back();
    m.partner_bloom.emplace_back();
  }
  m.setSpans(slot, box);
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
  return impl_->slot_of_id.find(id) != FlatHashMap::kMissing;
}

void SweepAndPrune::setBox(EntityId id, const Aabb& box) {
  Impl& m = *impl_;
  // Fast path without the hash lookup: the slot after the last one set.
  std::uint32_t slot = m.last_set + 1;
  if (slot >= m.ids.size() || m.ids[slot] != id || !m.inUse(slot)) slot = m.slotOfId(id);
  checkBox(box);
  m.setSpans(slot, box);
  m.last_set = slot;
}

void SweepAndPrune::update() {
  Impl& m = *impl_;
  if (!m.removed.empty()) m.dropRemoved(pairs_);
  m.rebuildBlooms();
  m.quantiseRanges();
  last_swaps_ = 0;
  for (int a = 0; a < 3; ++a) last_swaps_ += m.sortAxis(a);
  m.applyEvents(pairs_);
  if (!m.added.empty()) {
    const std::size_t entities = m.slot_of_id.size();
    // Room for a typical pair count, so steady-state ticks rarely grow them.
    // The hash index is left to grow with the pairs: small, it stays in cache.
    if (pairs_.capacity() < 2 * entities) {
      pairs_.reserve(2 * entities);
      m.pair_keys.reserve(2 * entities);
    }
    m.insertAdded(pairs_);
  }
}

std::size_t SweepAndPrune::size() const { return impl_->slot_of_id.size(); }

}  // namespace stc
