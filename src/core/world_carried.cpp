// World: what a tick carries over to the next (carried_state.hpp), out for
// a saved world and back into the loaded one.
#include "world_parts.hpp"

#include "carried_state.hpp"
#include "flat_hash_map.hpp"
#include "world_fracture.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace stc {
namespace {

void require(bool ok, const std::string& field, const char* reason) {
  if (!ok) throw InputError(field, reason);
}

std::string at(const char* part, std::size_t k) { return std::string(part) + "[" + std::to_string(k) + "]"; }

// Points [first, first + count) of `points` of size `size`, at most `most`.
void requireRange(std::uint32_t first, std::uint32_t count, std::size_t size, std::uint32_t most,
                  const std::string& field) {
  require(count <= most && std::uint64_t{first} + count <= size, field,
          "its points run past the points given (or more than a pair keeps)");
}

}  // namespace

CarriedState World::Parts::carriedState() const {
  const std::vector<EntityId>& ids = rows_.entityIds();
  const std::vector<BodyState>& bodies = rows_.bodies();
  CarriedState out;
  const std::size_t n = rows_.entityCount();
  for (std::size_t i = 0; i < n; ++i) {
    if (!bodies[i].is_static && !islands_.isSleeping(i)) {
      out.rest.push_back({static_cast<std::uint32_t>(i), islands_.rest(i)});
    }
  }
  out.next_group = islands_.nextGroup();
  const auto indexOfId = [&](EntityId id) { return rows_.indexMap().find(id); };
  constexpr std::uint32_t kMissing = detail::FlatHashMap::kMissing;
  if (broad_phase_.settled()) {
    out.boxes.reserve(n);
    for (std::size_t i = 0; i < n; ++i) out.boxes.push_back(broad_phase_.box(ids[i]));
    out.banding = broad_phase_.banding();
    for (EntityId& id : out.banding.slots) id = indexOfId(id);  // ids to dense indices
    for (auto& list : out.banding.endpoints) {
      for (std::vector<std::uint64_t>& band : list) {
        for (std::uint64_t& e : band) e = std::uint64_t{indexOfId(static_cast<EntityId>(e >> 1))} << 1 | (e & 1u);
      }
    }
    for (const BroadPair& pair : broad_phase_.pairs()) out.broad_pairs.push_back({indexOfId(pair.first), indexOfId(pair.second)});
  }
  const PairContactCache& cache = physics_.pairCache();
  for (const PairContactCache::Entry& e : cache.entries()) {
    const std::uint32_t a = indexOfId(static_cast<EntityId>(e.key >> 32));
    const std::uint32_t b = indexOfId(static_cast<EntityId>(e.key & 0xffffffffu));
    if (a == kMissing || b == kMissing) continue;
    CarriedState::CarriedEntry entry{a, b, e};
    entry.entry.first = static_cast<std::uint32_t>(out.carried_points.size());
    out.carried_points.insert(out.carried_points.end(), cache.points().begin() + e.first,
                              cache.points().begin() + e.first + e.count);
    out.carried.push_back(entry);
  }
  const WarmStartCache& warm_start = physics_.solver().warmStartCache();
  for (const WarmStartCache::Store& store : {warm_start.solved(), warm_start.held()}) {
    const bool held = store.manifolds == warm_start.held().manifolds;
    for (const WarmStartCache::Manifold& m : *store.manifolds) {
      const std::uint32_t a = indexOfId(static_cast<EntityId>(m.pair >> 32));
      const std::uint32_t b = indexOfId(static_cast<EntityId>(m.pair & 0xffffffffu));
      if (a == kMissing || b == kMissing) continue;
      CarriedState::Warm warm{a, b, held, m};
      warm.manifold.first = static_cast<std::uint32_t>(out.warm_points.size());
      out.warm_points.insert(out.warm_points.end(), store.points->begin() + m.first,
                             store.points->begin() + m.first + m.count);
      out.warm.push_back(warm);
    }
  }
  for (const WorldFracture::PendingBreak& b : fracture_->pendingBreaks()) {
    const std::uint32_t body = indexOfId(b.id);
    if (body != kMissing) out.breaks.push_back({body, b.plane});
  }
  return out;
}

void World::Parts::settleBroadPhase() {
  if (broad_phase_.settled()) return;
  broad_phase_.update();
  pairs_seen_.clear();  // its pairs' places moved
}

void World::Parts::restoreCarried(const CarriedState& state) {
  const std::vector<EntityId>& ids = rows_.entityIds();
  const std::vector<BodyState>& bodies = rows_.bodies();
  const std::size_t n = rows_.entityCount();
  // Everything checked before anything changes.
  for (std::size_t k = 0; k < state.rest.size(); ++k) {
    const CarriedState::Rest& r = state.rest[k];
    require(r.body < n && !bodies[r.body].is_static && !islands_.isSleeping(r.body), at("rest", k) + ".body",
            "not an awake movable body");
    bool ok = std::isfinite(r.state.rest_time) && r.state.rest_time >= 0.0 && std::isfinite(r.state.age) &&
              r.state.age >= 0.0;
    for (const Sphere& ball : r.state.balls) ok = ok && allFinite(ball.centre) && std::isfinite(ball.radius);
    require(ok, at("rest", k), "times finite and >= 0, balls finite");
  }
  require(state.next_group > 0, "next_group", "must be > 0");
  const bool broad = !state.boxes.empty();  // else the broad phase starts afresh
  require(!broad || state.boxes.size() == n, "boxes", "one a body");
  require(broad || state.broad_pairs.empty(), "broad_pairs", "not without boxes");
  for (std::size_t i = 0; i < state.boxes.size(); ++i) {
    const Aabb& box = state.boxes[i];
    require(allFinite(box.min) && allFinite(box.max) && (box.min.array() <= box.max.array()).all(), at("boxes", i),
            "corners finite, min <= max");
  }
  std::vector<BroadPair> pairs;
  pairs.reserve(state.broad_pairs.size());
  for (std::size_t k = 0; k < state.broad_pairs.size(); ++k) {
    const auto& p = state.broad_pairs[k];
    require(p[0] < n && p[1] < n && p[0] != p[1], at("broad_pairs", k), "two bodies of the world");
    pairs.push_back({std::min(ids[p[0]], ids[p[1]]), std::max(ids[p[0]], ids[p[1]])});
  }
  SweepAndPrune::Banding banding = state.banding;
  for (EntityId& body : banding.slots) {  // dense indices to ids
    require(body < n, "banding.slots", "a body of the world");
    body = ids[body];
  }
  for (auto& list : banding.endpoints) {  // dense indices to ids
    for (std::vector<std::uint64_t>& band : list) {
      for (std::uint64_t& e : band) {
        require(e >> 1 < n, "banding.endpoints", "a body of the world");
        e = std::uint64_t{ids[e >> 1]} << 1 | (e & 1u);
      }
    }
  }
  std::vector<PairContactCache::Entry> entries;
  entries.reserve(state.carried.size());
  for (std::size_t k = 0; k < state.carried.size(); ++k) {
    const CarriedState::CarriedEntry& c = state.carried[k];
    const PairContactCache::Entry& e = c.entry;
    require(c.a < n && c.b < n && c.a != c.b, at("carried", k), "two bodies of the world");
    require(allFinite(e.b_in_a) && e.a_to_b.coeffs().allFinite() && std::isfinite(e.tolerance), at("carried", k),
            "not finite");
    requireRange(e.first, e.count, state.carried_points.size(), 0xffffffffu, at("carried", k) + ".points");
    // The leaf pair a resumed test starts from: nodes of the two trees.
    const SphereTree& tree_a = shapes_.shapeAt(rows_.bodyShapes()[c.a]).tree;
    const SphereTree& tree_b = shapes_.shapeAt(rows_.bodyShapes()[c.b]).tree;
    require(e.leaf.a >= 0 && static_cast<std::size_t>(e.leaf.a) < tree_a.nodes().size() && e.leaf.b >= 0 &&
                static_cast<std::size_t>(e.leaf.b) < tree_b.nodes().size(),
            at("carried", k) + ".leaf", "not a node of each body's tree");
    require(e.level >= 0 && e.level < std::max(tree_a.levelCount(), tree_b.levelCount()), at("carried", k) + ".level",
            "not a level of the trees");
    entries.push_back(e);
    entries.back().key = entityPairKey(ids[c.a], ids[c.b]);
  }
  for (std::size_t k = 0; k < state.carried_points.size(); ++k) {
    const PairContactCache::Point& p = state.carried_points[k];
    require(allFinite(p.on_a) && allFinite(p.on_b) && allFinite(p.normal) && std::isfinite(p.depth) &&
                std::isfinite(p.separation) && std::isfinite(p.sphere_bound),
            at("carried_points", k), "not finite");
  }
  std::vector<WarmStartCache::Manifold> solved, held;
  std::vector<WarmStartCache::Point> solved_points, held_points;
  for (std::size_t k = 0; k < state.warm.size(); ++k) {
    const CarriedState::Warm& w = state.warm[k];
    require(w.a < n && w.b < n && w.a != w.b, at("warm", k), "two bodies of the world");
    require(allFinite(w.manifold.rolling), at("warm", k), "not finite");
    requireRange(w.manifold.first, w.manifold.count, state.warm_points.size(), WarmStartCache::kMaxPoints,
                 at("warm", k) + ".points");
    std::vector<WarmStartCache::Point>& points = w.held ? held_points : solved_points;
    WarmStartCache::Manifold m = w.manifold;
    m.pair = entityPairKey(ids[w.a], ids[w.b]);
    m.index_a = w.a;
    m.index_b = w.b;
    m.first = static_cast<std::uint32_t>(points.size());
    points.insert(points.end(), state.warm_points.begin() + w.manifold.first,
                  state.warm_points.begin() + w.manifold.first + w.manifold.count);
    (w.held ? held : solved).push_back(m);
  }
  for (std::size_t k = 0; k < state.warm_points.size(); ++k) {
    const WarmStartCache::Point& p = state.warm_points[k];
    require(allFinite(p.local_a) && std::isfinite(p.normal) && allFinite(p.friction), at("warm_points", k), "not finite");
  }

  std::vector<WorldFracture::PendingBreak> breaks;
  for (std::size_t k = 0; k < state.breaks.size(); ++k) {
    const CarriedState::Break& b = state.breaks[k];
    require(b.body < n && !bodies[b.body].is_static && bodies[b.body].material.strength > 0.0,
            at("breaks", k) + ".body", "not a movable body with a strength");
    require(allFinite(b.plane.point) && allFinite(b.plane.normal) && b.plane.normal.norm() > 0.0, at("breaks", k),
            "plane point and normal finite, normal not zero");
    const bool twice = std::any_of(breaks.begin(), breaks.end(),
                                   [&](const WorldFracture::PendingBreak& p) { return p.id == ids[b.body]; });
    require(!twice, at("breaks", k) + ".body", "queued twice");
    breaks.push_back({ids[b.body], b.plane});
  }

  // The broad phase last: its pairs must be those of the boxes (else it
  // throws, and the boxes it had are put back).
  if (broad) {
    std::vector<Aabb> had;
    had.reserve(n);
    for (std::size_t i = 0; i < n; ++i) had.push_back(broad_phase_.box(ids[i]));
    try {
      for (std::size_t i = 0; i < n; ++i) broad_phase_.setBox(ids[i], state.boxes[i]);
      broad_phase_.restore(banding, pairs);
    } catch (const InputError& e) {
      for (std::size_t i = 0; i < n; ++i) broad_phase_.setBox(ids[i], had[i]);
      throw InputError(e.field() == "pairs" ? "broad_pairs" : e.field(), e.reason());
    }
  }
  pairs_seen_.clear();
  for (const CarriedState::Rest& r : state.rest) islands_.restoreRest(r.body, r.state);
  islands_.setNextGroup(state.next_group);
  // The static bodies' covered faces measured now, as the saved world had
  // them: measured at the first tick, they would drop the carried contacts.
  static_cover_.update(rows_.bodies(), rows_.bodyShapes(), shapes_.coverShapes());
  physics_.restoreCarried(entries, state.carried_points);
  physics_.solver().warmStartCache().restore(std::move(solved), std::move(solved_points), std::move(held), std::move(held_points));
  fracture_->restorePending(std::move(breaks));
  invalidateLastTick();
}

}  // namespace stc
