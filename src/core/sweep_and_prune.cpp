// SweepAndPrune: I-COLLIDE sweep-and-prune (paper 3.2), with banded lists.
//
// Per axis, endpoints {value, slot, is_max} kept sorted by insertion sort.
// Sorting order: value, then min before max at equal value, so "a.min
// precedes b.max" is exactly "a.min <= b.max" (Aabb::overlaps counts touching
// boxes). Insertion sort swaps every inverted pair exactly once, and a pair's
// overlap can only change when one of its min/max orders changes, so the swaps
// keep the overlap set exact:
//   a min moves left past a max  -> the pair may start overlapping (join);
//   a max moves left past a min  -> the pair is now separated on this axis.
//
// Bands. One list per axis holding every box makes each endpoint pass every
// box that moves past it along that axis however far away on the other axes:
// swaps grow as N^(5/3) at constant density. So each axis's list is split into
// bands along the next axis (x lists by y, y by z, z by x); a box is in every
// band its extent there touches. Two boxes that overlap share a band on every
// list. Bands are sorted before memberships change, so a pair that overlapped
// (shared a band) has its flips seen there; a pair that starts overlapping
// either shared a band before too, or one box just entered their common band,
// and a local sweep of that band on entry finds the new pairs. With one band
// this is the classic single list.
//
// Filters that need no random memory access drop most swaps in the sort:
//   join:     each endpoint carries its box's ranges on the two other axes,
//             quantised monotonically to 8 bits (conservative);
//   separate: each slot has a 64-bit Bloom mask of its current partners' slots.
// Surviving events are applied after all lists are sorted.
//
// Boxes that did not move. A box set to the box it already had is not marked;
// an update that touches few boxes sorts only the bands that hold a marked one
// (the others are sorted and their endpoints current), quantises only the
// marked and added boxes with the last full update's quantisers (any monotone
// map keeps the filter conservative) and moves only them between bands; the
// Bloom masks keep their stale bits until the next full update (a stale bit
// only lets a swap through as a no-op event). The pairs, and their order, are
// those of a full update.
#include "sweep_and_prune.hpp"

#include "flat_hash_map.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>

namespace stc {
namespace {

using detail::FlatHashMap;

struct Endpoint {
  double value;
  std::uint32_t tag;     // slot << 1 | is_max
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

// Monotone map of a coordinate to 0..top: a <= b implies q(a) <= q(b), so the
// images of overlapping intervals overlap. Used for the 8-bit filter ranges
// and for band indices.
struct Quantiser {
  double origin = 0.0;
  double scale = 0.0;
  double top = 0.0;
  std::uint32_t operator()(double v) const {
    const double x = (v - origin) * scale;  // NaN only when scale is 0: maps to 0 like all
    return x > 0.0 ? static_cast<std::uint32_t>(std::min(x, top)) : 0u;
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
  kLive,     // endpoints in the lists
  kRemoved,  // removed since the last update(); endpoints and pairs still there
};

void checkBox(const Aabb& a) {
  if (!a.min.allFinite() || !a.max.allFinite())
    throw InputError("box", "box corners must be finite");
  if (!(a.min.array() <= a.max.array()).all())
    throw InputError("box", "box min must be <= max on every axis");
}

constexpr std::uint32_t kMaxBands = 256;
// Band width in mean box extents: wider bands, fewer duplicates; narrower,
// fewer swaps. 4: a box is in 1.25 bands on average.
constexpr double kBandWidthInBoxes = 4.0;
constexpr std::size_t kLookAhead = 8;  // prefetch distance of the span reads

// The lists of one axis: bands along the next axis.
struct AxisLists {
  Quantiser band_of;  // coordinate on the band axis -> band
  std::vector<std::vector<Endpoint>> bands;
  std::vector<std::uint8_t> band_lost;  // by band: a box left it this update
  std::vector<std::uint8_t> band_dirty;  // by band: holds a box that moved (incremental update)
  std::vector<std::uint16_t> lo, hi;    // by slot: bands the box is in now
  std::vector<std::uint16_t> new_lo, new_hi;  // by slot: bands it must be in
  double max_extent = 0.0;                    // on this axis, over boxes in use
};

}  // namespace

struct SweepAndPrune::Impl {
  AxisLists lists[3];
  std::vector<Span> spans[3];    // by slot, per axis: the box for the next update()
  std::vector<EntityId> ids;     // by slot
  std::vector<SlotState> state;  // by slot
  std::vector<std::uint64_t> partner_bloom;  // by slot, rebuilt each update()
  std::vector<std::uint32_t> free_slots;
  std::vector<std::uint32_t> added;    // slots to insert at the next update()
  std::vector<std::uint32_t> removed;  // slots to drop at the next update()
  std::vector<std::uint32_t> removed_live;  // of those, the ones with endpoints and pairs
  FlatHashMap slot_of_id;
  std::uint32_t last_set = ~0u;  // slot of the last setBox: callers often go in add order
  std::size_t live_at_banding = 0;  // boxes when the bands were last chosen

  // Live boxes set to a new box since the last update() (by slot, and
  // listed), until more moved than an incremental update takes.
  std::vector<std::uint8_t> moved;
  std::vector<std::uint32_t> moved_slots;
  bool many_moved = false;
  // A full update at least this often: fresh quantisers and Bloom masks keep
  // the filters sharp.
  static constexpr int kFullEvery = 64;
  // The last full quantise's maps of each axis (for the filter ranges), and
  // the updates since it (the first update is a full one).
  Quantiser filter_q[3];
  int updates_since_full = kFullEvery;
  bool updated = false;  // update() ran at least once

  // Pair set: pairs (owned by SweepAndPrune) and pair_keys are parallel dense
  // arrays; pair_index maps a key to its index there.
  std::vector<std::uint64_t> pair_keys;
  FlatHashMap pair_index;
  // Each slot's pairs, a doubly linked list through the pair array: end 0 of
  // pair i is its lower slot (key >> 32), end 1 its higher; pair_links[i]
  // holds the previous and next pair of each end's list (kNoPair ends it),
  // first_pair (by slot) each list's head. Kept as pairs come, go and move,
  // so a box's pairs are found without a walk over all pairs.
  static constexpr std::uint32_t kNoPair = ~0u;
  struct PairLinks {
    std::uint32_t prev[2];
    std::uint32_t next[2];
  };
  std::vector<PairLinks> pair_links;
  std::vector<std::uint32_t> first_pair;
  std::vector<std::uint32_t> dropped;  // dropRemoved: the places of the pairs it drops

  // Swaps that may change the pair set: moving slot << 32 | kind | passed slot;
  // events[0, event_count) are this update's, the rest is room.
  static constexpr std::uint64_t kSeparate = 1u << 31;
  std::vector<std::uint64_t> events;
  std::size_t event_count = 0;

  std::vector<std::uint64_t> entering;  // band << 32 | slot, boxes to insert into bands
  std::vector<Endpoint> scratch;        // new endpoints of one band, sorted before merging

  // --- slots and pairs -------------------------------------------------------

  std::uint32_t slotOfId(EntityId id) const {
    const std::uint32_t slot = slot_of_id.find(id);
    if (slot == FlatHashMap::kMissing) throw InputError("id", "unknown entity id " + std::to_string(id));
    return slot;
  }

  bool inUse(std::size_t slot) const {
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

  // --- each slot's list of pairs ---

  static std::uint32_t slotAt(std::uint64_t key, int end) {
    return static_cast<std::uint32_t>(end == 0 ? key >> 32 : key & 0xFFFFFFFFu);
  }
  // The end of pair i that is `slot`.
  int endOf(std::uint32_t i, std::uint32_t slot) const { return slotAt(pair_keys[i], 0) == slot ? 0 : 1; }
  // The link that points at pair i from the front of `slot`'s list.
  std::uint32_t& linkBefore(std::uint32_t prev, std::uint32_t slot) {
    return prev == kNoPair ? first_pair[slot] : pair_links[prev].next[endOf(prev, slot)];
  }

  // Pair i (its key set) put at the head of its slots' lists.
  void link(std::uint32_t i) {
    for (int end = 0; end < 2; ++end) {
      const std::uint32_t s = slotAt(pair_keys[i], end);
      const std::uint32_t next = first_pair[s];
      pair_links[i].prev[end] = kNoPair;
      pair_links[i].next[end] = next;
      if (next != kNoPair) pair_links[next].prev[endOf(next, s)] = i;
      first_pair[s] = i;
    }
  }

  void unlink(std::uint32_t i) {
    for (int end = 0; end < 2; ++end) {
      const std::uint32_t s = slotAt(pair_keys[i], end);
      const std::uint32_t prev = pair_links[i].prev[end], next = pair_links[i].next[end];
      linkBefore(prev, s) = next;
      if (next != kNoPair) pair_links[next].prev[endOf(next, s)] = prev;
    }
  }

  // The pair at `from` moved to `to` (key and links copied): its neighbours
  // point at `to`.
  void relink(std::uint32_t to) {
    for (int end = 0; end < 2; ++end) {
      const std::uint32_t s = slotAt(pair_keys[to], end);
      const std::uint32_t prev = pair_links[to].prev[end], next = pair_links[to].next[end];
      linkBefore(prev, s) = to;
      if (next != kNoPair) pair_links[next].prev[endOf(next, s)] = to;
    }
  }

  // --- the pair set ---

  void addPair(std::uint32_t a, std::uint32_t b, std::vector<BroadPair>& pairs) {
    const std::uint64_t key = pairKey(a, b);
    if (pair_index.find(key) != FlatHashMap::kMissing) return;
    const auto i = static_cast<std::uint32_t>(pairs.size());
    pair_index.set(key, i);
    const EntityId ia = ids[a], ib = ids[b];
    pairs.push_back(ia < ib ? BroadPair{ia, ib} : BroadPair{ib, ia});
    pair_keys.push_back(key);
    pair_links.emplace_back();
    link(i);
    partner_bloom[a] |= bloomBit(b);
    partner_bloom[b] |= bloomBit(a);
  }

  // The last pair moved to `index`, whose pair is gone (unlinked, out of the index).
  void fillFromLast(std::size_t index, std::vector<BroadPair>& pairs) {
    const std::size_t last = pairs.size() - 1;
    if (index != last) {
      pairs[index] = pairs[last];
      pair_keys[index] = pair_keys[last];
      pair_links[index] = pair_links[last];
      relink(static_cast<std::uint32_t>(index));
      pair_index.set(pair_keys[index], static_cast<std::uint32_t>(index));
    }
    pairs.pop_back();
    pair_keys.pop_back();
    pair_links.pop_back();
  }

  void removePairAt(std::size_t index, std::vector<BroadPair>& pairs) {
    unlink(static_cast<std::uint32_t>(index));
    pair_index.erase(pair_keys[index]);
    fillFromLast(index, pairs);
  }

  void removePair(std::uint32_t a, std::uint32_t b, std::vector<BroadPair>& pairs) {
    const std::uint32_t index = pair_index.find(pairKey(a, b));
    if (index != FlatHashMap::kMissing) removePairAt(index, pairs);
  }

  // Drop the endpoints and pairs of removed slots and free the slots: the
  // bands that held a removed box, and its pairs through its list, so the
  // cost follows the removed boxes, not the world.
  void dropRemoved(std::vector<BroadPair>& pairs) {
    for (AxisLists& list : lists) {
      for (const std::uint32_t slot : removed_live) {
        for (std::uint32_t b = list.lo[slot]; b <= list.hi[slot]; ++b) list.band_lost[b] = 1;
      }
      for (std::size_t b = 0; b < list.bands.size(); ++b) {
        if (!list.band_lost[b]) continue;
        list.band_lost[b] = 0;
        std::vector<Endpoint>& band = list.bands[b];
        band.erase(std::remove_if(band.begin(), band.end(),
                                  [&](const Endpoint& e) { return state[slotOf(e)] == SlotState::kRemoved; }),
                   band.end());
      }
    }
    dropRemovedPairs(pairs);
    for (const std::uint32_t slot : removed) {
      state[slot] = SlotState::kFree;
      first_pair[slot] = kNoPair;
      free_slots.push_back(slot);
    }
    removed.clear();
    removed_live.clear();
  }

  // The pairs of removed slots, left as a walk up the whole array would
  // leave them that drops each at its place and moves the last pair there
  // (the order the pairs always had): a place dropped takes the last pair
  // not dropped; dropped pairs at the end just go.
  void dropRemovedPairs(std::vector<BroadPair>& pairs) {
    dropped.clear();
    for (const std::uint32_t slot : removed_live) {
      for (std::uint32_t i = first_pair[slot]; i != kNoPair; i = pair_links[i].next[endOf(i, slot)]) {
        dropped.push_back(i);
      }
    }
    std::sort(dropped.begin(), dropped.end());
    dropped.erase(std::unique(dropped.begin(), dropped.end()), dropped.end());
    for (const std::uint32_t i : dropped) {
      unlink(i);
      pair_index.erase(pair_keys[i]);
    }
    std::size_t lo = 0, hi = dropped.size();
    while (lo < hi) {
      if (dropped[hi - 1] == pairs.size() - 1) {  // dropped, at the end
        pairs.pop_back();
        pair_keys.pop_back();
        pair_links.pop_back();
        --hi;
      } else {
        fillFromLast(dropped[lo++], pairs);
      }
    }
#ifndef NDEBUG
    for (const std::uint64_t key : pair_keys) {
      assert(state[slotAt(key, 0)] != SlotState::kRemoved && state[slotAt(key, 1)] != SlotState::kRemoved);
    }
#endif
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

  // --- bands -------------------------------------------------------------------

  // Choose the bands from the boxes in use and put every box back as if just
  // added (so its pairs are found again by the local sweeps). Done when the
  // box count has changed by 2x since the last choice: amortised O(1) per add.
  void chooseBands(std::vector<BroadPair>& pairs) {
    std::size_t in_use = 0;
    for (int a = 0; a < 3; ++a) {
      const int band_axis = (a + 1) % 3;
      double lo = INFINITY, hi = -INFINITY, extent_sum = 0.0;
      in_use = 0;
      for (std::size_t s = 0; s < state.size(); ++s) {
        if (!inUse(s)) continue;
        const Span& span = spans[band_axis][s];
        lo = std::min(lo, span.min);
        hi = std::max(hi, span.max);
        extent_sum += span.max - span.min;
        ++in_use;
      }
      Quantiser q;
      const double extent = hi - lo;
      if (in_use > 0 && extent > 0.0 && std::isfinite(extent)) {
        const double mean = extent_sum / static_cast<double>(in_use);
        const double width = std::max(kBandWidthInBoxes * mean, extent / kMaxBands);
        q.origin = lo;
        q.scale = 1.0 / width;
        q.top = std::floor(extent / width);  // boxes beyond the ends go to the end bands
      }
      setBands(a, q, in_use);
    }
    putBackAll(pairs);
    live_at_banding = in_use;
  }

  // List a's bands: `q` maps a coordinate to one, for `in_use` boxes.
  void setBands(int a, const Quantiser& q, std::size_t in_use) {
    lists[a].band_of = q;
    lists[a].bands.resize(static_cast<std::size_t>(q.top) + 1);
    lists[a].band_lost.assign(lists[a].bands.size(), 0);
    lists[a].band_dirty.assign(lists[a].bands.size(), 0);
    // Room in each band for twice its even share of the endpoints (two a
    // box, a box in at most two bands): grown only as a band first passed
    // its high, a steady scene whose boxes drift between bands allocated in
    // a tick long after its start (the swept allocation test, once its
    // trajectory changed).
    const std::size_t share = 2 * 2 * in_use / lists[a].bands.size() + 16;
    for (std::vector<Endpoint>& band : lists[a].bands) {
      band.clear();
      band.reserve(2 * share);
    }
  }

  // Each band's endpoints (the same ones, id << 1 | is_max) put in `order`,
  // which must keep them sorted: only endpoints of equal value move.
  bool reorderBands(const std::array<std::vector<std::vector<std::uint64_t>>, 3>& order) {
    std::vector<std::uint64_t> have, want;
    for (int a = 0; a < 3; ++a) {
      std::vector<std::vector<Endpoint>>& bands = lists[a].bands;
      if (order[a].size() != bands.size()) return false;
      for (std::size_t b = 0; b < bands.size(); ++b) {
        std::vector<Endpoint>& band = bands[b];
        const std::vector<std::uint64_t>& tags = order[a][b];
        if (tags.size() != band.size()) return false;
        have.clear();
        want.clear();
        for (const Endpoint& e : band) have.push_back(e.tag);
        for (const std::uint64_t tag : tags) {
          const std::uint32_t slot = slot_of_id.find(static_cast<EntityId>(tag >> 1));
          if (tag >> 33 != 0 || slot == FlatHashMap::kMissing) return false;
          want.push_back(std::uint64_t{slot} << 1 | (tag & 1u));
        }
        std::vector<std::uint64_t> wanted = want;
        std::sort(have.begin(), have.end());
        std::sort(wanted.begin(), wanted.end());
        if (have != wanted) return false;
        const Span* span = spans[a].data();
        for (std::size_t k = 0; k < band.size(); ++k) {
          const std::uint32_t tag = static_cast<std::uint32_t>(want[k]);
          const Span& sp = span[tag >> 1];
          band[k] = Endpoint{(tag & 1u) != 0 ? sp.max : sp.min, tag, sp.others};
          if (k > 0 && before(band[k], band[k - 1])) return false;
        }
      }
    }
    return true;
  }

  // The pairs (the same set) put in `order`, their keys, links and index with them.
  bool reorderPairs(const std::vector<BroadPair>& order, std::vector<BroadPair>& pairs) {
    if (order.size() != pairs.size()) return false;
    std::vector<std::uint64_t> keys;
    keys.reserve(order.size());
    for (const BroadPair& pair : order) {
      const std::uint32_t a = slot_of_id.find(pair.first), b = slot_of_id.find(pair.second);
      if (a == FlatHashMap::kMissing || b == FlatHashMap::kMissing || a == b) return false;
      const std::uint32_t at = pair_index.find(pairKey(a, b));
      if (at == FlatHashMap::kMissing || !(pairs[at] == pair)) return false;
      keys.push_back(pairKey(a, b));
    }
    std::vector<std::uint64_t> sorted = keys;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) return false;  // a pair twice
    pairs = order;
    pair_keys = std::move(keys);
    pair_links.assign(pairs.size(), PairLinks{});
    std::fill(first_pair.begin(), first_pair.end(), kNoPair);
    pair_index = FlatHashMap();
    for (std::uint32_t i = 0; i < pairs.size(); ++i) {
      pair_index.set(pair_keys[i], i);
      link(i);
    }
    return true;
  }

  // Every box put back as if just added (its pairs found again by the local
  // sweeps at the next update), no pair left.
  void putBackAll(std::vector<BroadPair>& pairs) {
    pairs.clear();
    pair_keys.clear();
    pair_links.clear();
    std::fill(first_pair.begin(), first_pair.end(), kNoPair);
    pair_index = FlatHashMap();
    added.clear();
    for (std::size_t s = 0; s < state.size(); ++s) {
      if (!inUse(s)) continue;
      state[s] = SlotState::kAdded;
      added.push_back(static_cast<std::uint32_t>(s));
    }
  }

  bool bandsStale() const {
    const std::size_t n = slot_of_id.size();
    if (live_at_banding == 0) return n > 0;
    return n > 2 * live_at_banding || 2 * n < live_at_banding;
  }

  // Quantise every box over the bounds of all boxes into the others field of
  // its spans (the endpoints copy it when sorted), and find the bands each box
  // must be in.
  void quantise() {
    const std::size_t slots = state.size();
    Quantiser q[3];
    for (int a = 0; a < 3; ++a) {
      double lo = INFINITY, hi = -INFINITY, max_extent = 0.0;
      for (std::size_t s = 0; s < slots; ++s) {
        if (!inUse(s)) continue;
        lo = std::min(lo, spans[a][s].min);
        hi = std::max(hi, spans[a][s].max);
        max_extent = std::max(max_extent, spans[a][s].max - spans[a][s].min);
      }
      q[a].origin = lo <= hi ? lo : 0.0;
      const double extent = hi - lo;
      // Zero or overflowing extent: scale 0 maps all to 0, still conservative.
      q[a].scale = extent > 0.0 && std::isfinite(extent) ? 255.0 / extent : 0.0;
      q[a].top = 255.0;
      filter_q[a] = q[a];
      lists[a].max_extent = max_extent;
    }
    sizeBandRanges();
    for (std::size_t s = 0; s < slots; ++s) {
      if (inUse(s)) quantiseBox(static_cast<std::uint32_t>(s));
    }
  }

  // The per-slot band ranges of every list, one entry a slot.
  void sizeBandRanges() {
    for (AxisLists& list : lists) {
      list.lo.resize(state.size());
      list.hi.resize(state.size());
      list.new_lo.resize(state.size());
      list.new_hi.resize(state.size());
    }
  }

  // One box's filter ranges (the saved quantisers) and the bands it must be in.
  void quantiseBox(std::uint32_t s) {
    std::uint32_t range[3];
    for (int a = 0; a < 3; ++a) range[a] = filter_q[a](spans[a][s].min) | (filter_q[a](spans[a][s].max) << 8);
    for (int a = 0; a < 3; ++a) {
      spans[a][s].others = range[(a + 1) % 3] | (range[(a + 2) % 3] << 16);
      const Span& band_span = spans[(a + 1) % 3][s];
      lists[a].new_lo[s] = static_cast<std::uint16_t>(lists[a].band_of(band_span.min));
      lists[a].new_hi[s] = static_cast<std::uint16_t>(lists[a].band_of(band_span.max));
    }
  }

  // Few boxes moved or were added: those alone are quantised, and the bands
  // holding a moved one are marked for sorting. max_extent stays an upper
  // bound (it only grows here), which is all the sweeps need.
  void quantiseMoved() {
    sizeBandRanges();
    const auto one = [&](std::uint32_t s) {
      quantiseBox(s);
      for (int a = 0; a < 3; ++a) {
        lists[a].max_extent = std::max(lists[a].max_extent, spans[a][s].max - spans[a][s].min);
      }
    };
    for (std::uint32_t s : moved_slots) {
      if (state[s] != SlotState::kLive) continue;
      one(s);
      for (AxisLists& list : lists) {
        for (std::uint32_t b = list.lo[s]; b <= list.hi[s]; ++b) list.band_dirty[b] = 1;
      }
    }
    for (std::uint32_t s : added) {
      if (state[s] == SlotState::kAdded) one(s);
    }
  }

  // --- sorting -----------------------------------------------------------------

  // Refresh and insertion-sort one band, recording the min/max swaps that pass
  // the filters as events. The inner loop is branch-free but for its exit: an
  // event is always written, the cursor advanced only when it counts.
  // Returns the number of swaps.
  std::size_t sortBand(std::vector<Endpoint>& band, const Span* span) {
    Endpoint* e = band.data();
    const std::size_t n = band.size();
    const std::uint64_t* bloom = partner_bloom.data();
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

  // Apply the events. Order does not matter: a join adds a pair only if the
  // boxes overlap on every axis now, and a pair with a separate event does not.
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

  // --- boxes entering and leaving bands ----------------------------------------

  // Merge the boxes listed in `entering` (band << 32 | slot) into the bands of
  // list a; with `sweep`, then look for each box's pairs in the band it entered.
  void insertEntering(int a, bool sweep, std::vector<BroadPair>& pairs) {
    std::sort(entering.begin(), entering.end());
    const Span* span = spans[a].data();
    for (std::size_t g = 0; g < entering.size();) {
      const auto b = static_cast<std::uint32_t>(entering[g] >> 32);
      std::size_t end = g;
      scratch.clear();
      for (; end < entering.size() && (entering[end] >> 32) == b; ++end) {
        const auto s = static_cast<std::uint32_t>(entering[end]);
        scratch.push_back({span[s].min, s << 1, span[s].others});
        scratch.push_back({span[s].max, (s << 1) | 1u, span[s].others});
      }
      std::sort(scratch.begin(), scratch.end(), before);
      std::vector<Endpoint>& band = lists[a].bands[b];
      std::size_t i = band.size(), j = scratch.size();
      band.resize(i + j);
      for (std::size_t w = band.size(); j > 0;) {
        if (i > 0 && before(scratch[j - 1], band[i - 1]))
          band[--w] = band[--i];
        else
          band[--w] = scratch[--j];
      }
      for (; g < end; ++g)
        if (sweep) sweepBand(a, band, static_cast<std::uint32_t>(entering[g]), pairs);
    }
    entering.clear();
  }

  // Pairs of box s among the boxes of one band of list a: every box overlapping
  // s on axis a has its min in [s.min - max_extent, s.max] (with a margin for
  // rounding).
  void sweepBand(int a, const std::vector<Endpoint>& band, std::uint32_t s, std::vector<BroadPair>& pairs) {
    const Span& sp = spans[a][s];
    const double width = lists[a].max_extent;
    const double from = sp.min - width - 1e-9 * (std::abs(sp.min) + width);
    auto it = std::lower_bound(band.begin(), band.end(), from,
                               [](const Endpoint& e, double v) { return e.value < v; });
    for (; it != band.end() && it->value <= sp.max; ++it) {
      if (isMax(*it) || !rangesMayOverlap(sp.others, it->others)) continue;
      const std::uint32_t t = slotOf(*it);
      if (t != s && overlaps(s, t)) addPair(s, t, pairs);
    }
  }

  // Move live boxes whose band range changed on list a (after the sort, which
  // saw their flips in the bands they leave): drop them from bands they left,
  // add them to bands they entered, finding their pairs there.
  // With `only_moved`, only the moved boxes are looked at (the others kept
  // their bands); `entering` is sorted before use, so the order is free.
  void moveBands(int a, std::vector<BroadPair>& pairs, bool only_moved) {
    AxisLists& list = lists[a];
    const auto move = [&](std::size_t s) {
      if (state[s] != SlotState::kLive) return;
      const std::uint32_t lo = list.lo[s], hi = list.hi[s], nlo = list.new_lo[s], nhi = list.new_hi[s];
      if (lo == nlo && hi == nhi) return;
      for (std::uint32_t b = lo; b <= hi; ++b)
        if (b < nlo || b > nhi) list.band_lost[b] = 1;
      for (std::uint32_t b = nlo; b <= nhi; ++b)
        if (b < lo || b > hi) entering.push_back((std::uint64_t{b} << 32) | s);
      list.lo[s] = static_cast<std::uint16_t>(nlo);
      list.hi[s] = static_cast<std::uint16_t>(nhi);
    };
    if (only_moved) {
      for (std::uint32_t s : moved_slots) move(s);
    } else {
      for (std::size_t s = 0; s < state.size(); ++s) move(s);
    }
    for (std::size_t b = 0; b < list.bands.size(); ++b) {
      if (!list.band_lost[b]) continue;
      list.band_lost[b] = 0;
      std::vector<Endpoint>& band = list.bands[b];
      band.erase(std::remove_if(band.begin(), band.end(),
                                [&](const Endpoint& e) {
                                  const std::uint32_t t = slotOf(e);
                                  return b < list.lo[t] || b > list.hi[t];
                                }),
                 band.end());
    }
    insertEntering(a, /*sweep=*/true, pairs);
  }

  // New boxes: into their bands on every list; pairs from the x lists' sweeps
  // (two overlapping boxes share an x-list band).
  void insertAdded(std::vector<BroadPair>& pairs) {
    // Slots removed again before this update were freed by dropRemoved().
    added.erase(std::remove_if(added.begin(), added.end(),
                               [&](std::uint32_t s) { return state[s] != SlotState::kAdded; }),
                added.end());
    if (added.empty()) return;
    for (std::uint32_t s : added) state[s] = SlotState::kLive;
    for (int a = 0; a < 3; ++a) {
      AxisLists& list = lists[a];
      for (std::uint32_t s : added) {
        list.lo[s] = list.new_lo[s];
        list.hi[s] = list.new_hi[s];
        for (std::uint32_t b = list.lo[s]; b <= list.hi[s]; ++b) entering.push_back((std::uint64_t{b} << 32) | s);
      }
      insertEntering(a, /*sweep=*/a == 0, pairs);
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
    m.moved.emplace_back();
    m.first_pair.push_back(Impl::kNoPair);
  }
  m.setSpans(slot, box);
  m.ids[slot] = id;
  m.state[slot] = SlotState::kAdded;
  m.slot_of_id.set(id, slot);
  m.added.push_back(slot);
}

void SweepAndPrune::releaseMemory() {
  const Impl& m = *impl_;
  SweepAndPrune fitted;
  for (std::uint32_t slot = 0; slot < m.state.size(); ++slot) {
    if (m.state[slot] == SlotState::kAdded || m.state[slot] == SlotState::kLive) {
      fitted.add(m.ids[slot], box(m.ids[slot]));
    }
  }
  fitted.update();
  fitted.last_swaps_ = last_swaps_;
  *this = std::move(fitted);
}

bool SweepAndPrune::settled() const {
  const Impl& m = *impl_;
  return m.updated && m.added.empty() && m.removed.empty();
}

SweepAndPrune::Banding SweepAndPrune::banding() const {
  const Impl& m = *impl_;
  Banding out;
  for (int a = 0; a < 3; ++a) {
    out.origin[a] = m.lists[a].band_of.origin;
    out.scale[a] = m.lists[a].band_of.scale;
    out.top[a] = m.lists[a].band_of.top;
  }
  out.chosen_for = m.live_at_banding;
  for (std::uint32_t slot = 0; slot < m.state.size(); ++slot) {
    if (m.inUse(slot)) out.slots.push_back(m.ids[slot]);
  }
  for (int a = 0; a < 3; ++a) {
    for (const std::vector<Endpoint>& band : m.lists[a].bands) {
      std::vector<std::uint64_t>& order = out.endpoints[a].emplace_back();
      order.reserve(band.size());
      for (const Endpoint& e : band) order.push_back(std::uint64_t{m.ids[slotOf(e)]} << 1 | isMax(e));
    }
  }
  return out;
}

void SweepAndPrune::restore(const Banding& banding, const std::vector<BroadPair>& order) {
  for (int a = 0; a < 3; ++a) {
    const double top = banding.top[a];
    if (!(std::isfinite(banding.origin[a]) && std::isfinite(banding.scale[a]) && banding.scale[a] >= 0.0 &&
          top >= 0.0 && top < kMaxBands && top == std::floor(top))) {
      throw InputError("banding", "origin and scale finite (scale >= 0), top a whole number of bands below " +
                                      std::to_string(kMaxBands));
    }
  }
  const Impl& m = *impl_;
  SweepAndPrune fitted;  // as releaseMemory, the boxes in the slot order given
  for (const EntityId id : banding.slots) {
    if (!contains(id) || fitted.contains(id)) throw InputError("banding", "slots: not each box's id once");
    fitted.add(id, box(id));
  }
  Impl& f = *fitted.impl_;
  if (f.state.size() != m.slot_of_id.size()) throw InputError("banding", "slots: not each box's id once");
  std::size_t in_use = f.state.size();
  if (banding.chosen_for == 0 ? in_use > 0 : (in_use > 2 * banding.chosen_for || 2 * in_use < banding.chosen_for)) {
    throw InputError("banding", "chosen for " + std::to_string(banding.chosen_for) + " boxes, not near " +
                                    std::to_string(in_use));
  }
  for (int a = 0; a < 3; ++a) f.setBands(a, Quantiser{banding.origin[a], banding.scale[a], banding.top[a]}, in_use);
  f.live_at_banding = banding.chosen_for;
  fitted.update();
  if (!f.reorderBands(banding.endpoints)) {
    throw InputError("banding", "endpoints: not each band's endpoints of the boxes, in order");
  }
  if (!f.reorderPairs(order, fitted.pairs_)) throw InputError("pairs", "not the pairs of the boxes, each once");
  fitted.last_swaps_ = last_swaps_;
  *this = std::move(fitted);
}

void SweepAndPrune::remove(EntityId id) {
  Impl& m = *impl_;
  const std::uint32_t slot = m.slotOfId(id);
  m.slot_of_id.erase(id);
  if (m.state[slot] == SlotState::kLive) m.removed_live.push_back(slot);
  m.state[slot] = SlotState::kRemoved;
  m.removed.push_back(slot);
}

void SweepAndPrune::partnersOf(EntityId id, std::vector<EntityId>* out) const {
  const Impl& m = *impl_;
  const std::uint32_t slot = m.slotOfId(id);
  out->clear();
  for (std::uint32_t i = m.first_pair[slot]; i != Impl::kNoPair; i = m.pair_links[i].next[m.endOf(i, slot)]) {
    const std::uint32_t other = Impl::slotAt(m.pair_keys[i], 0) == slot ? Impl::slotAt(m.pair_keys[i], 1)
                                                                         : Impl::slotAt(m.pair_keys[i], 0);
    out->push_back(m.ids[other]);
  }
}

bool SweepAndPrune::contains(EntityId id) const {
  return impl_->slot_of_id.find(id) != FlatHashMap::kMissing;
}

Aabb SweepAndPrune::box(EntityId id) const {
  const Impl& m = *impl_;
  const std::uint32_t slot = m.slotOfId(id);
  Aabb out;
  for (int a = 0; a < 3; ++a) {
    out.min[a] = m.spans[a][slot].min;
    out.max[a] = m.spans[a][slot].max;
  }
  return out;
}

void SweepAndPrune::setBox(EntityId id, const Aabb& box) {
  Impl& m = *impl_;
  // Fast path without the hash lookup: the slot after the last one set.
  std::uint32_t slot = m.last_set + 1;
  if (slot >= m.ids.size() || m.ids[slot] != id || !m.inUse(slot)) slot = m.slotOfId(id);
  checkBox(box);
  m.last_set = slot;
  bool same = true;
  for (int a = 0; a < 3; ++a) {
    same = same && m.spans[a][slot].min == box.min[a] && m.spans[a][slot].max == box.max[a];
  }
  if (same) return;
  m.setSpans(slot, box);
  if (m.many_moved || m.state[slot] != SlotState::kLive || m.moved[slot] != 0) return;
  if (8 * (m.moved_slots.size() + 1) > m.slot_of_id.size()) {
    m.many_moved = true;  // the next update is a full one: no need to list more
    return;
  }
  m.moved[slot] = 1;
  m.moved_slots.push_back(slot);
}

void SweepAndPrune::update() {
  Impl& m = *impl_;
  m.updated = true;
  if (!m.removed.empty()) m.dropRemoved(pairs_);
  const bool rebanded = m.bandsStale();
  if (rebanded) m.chooseBands(pairs_);
  // Incremental while few boxes changed (a world mostly at rest, asleep or
  // still): their bands alone are sorted.
  const std::size_t touched = m.moved_slots.size() + m.added.size();
  const bool incremental = !rebanded && !m.many_moved && m.updates_since_full < Impl::kFullEvery && 8 * touched <= m.slot_of_id.size();
  if (incremental) {
    ++m.updates_since_full;
    m.quantiseMoved();
  } else {
    m.updates_since_full = 0;
    m.rebuildBlooms();
    m.quantise();
  }
  last_swaps_ = 0;
  for (int a = 0; a < 3; ++a) {
    AxisLists& list = m.lists[a];
    for (std::size_t b = 0; b < list.bands.size(); ++b) {
      if (incremental && list.band_dirty[b] == 0) continue;
      list.band_dirty[b] = 0;
      last_swaps_ += m.sortBand(list.bands[b], m.spans[a].data());
    }
  }
  m.applyEvents(pairs_);
  for (int a = 0; a < 3; ++a) m.moveBands(a, pairs_, incremental);
  for (std::uint32_t slot : m.moved_slots) m.moved[slot] = 0;
  m.moved_slots.clear();
  m.many_moved = false;
  if (!m.added.empty()) {
    const std::size_t entities = m.slot_of_id.size();
    // Room for a typical pair count, so steady-state ticks rarely grow them.
    // The hash index is left to grow with the pairs: small, it stays in cache.
    if (pairs_.capacity() < 2 * entities) {
      pairs_.reserve(2 * entities);
      m.pair_keys.reserve(2 * entities);
      m.pair_links.reserve(2 * entities);
    }
    m.insertAdded(pairs_);
  }
}

std::size_t SweepAndPrune::size() const { return impl_->slot_of_id.size(); }

}  // namespace stc
