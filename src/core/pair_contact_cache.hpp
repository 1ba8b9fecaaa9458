// PairContactCache: a body pair's contacts carried from the tick they were
// built to the next ticks while the two bodies barely move relative to each
// other (the idea of Jolt's body-pair cache). A resting pile's pairs then
// skip the narrow phase and contact building: the response places their
// contacts again at the bodies' new poses, from points fixed in each body.
#pragma once

#include "pair_test.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/types.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace stc {

namespace detail {
class FlatHashMap;  // src/core/flat_hash_map.hpp
}

// What a pair's entry needs of its two bodies.
struct ReuseBody {
  EntityId id = kInvalidEntity;
  const Pose* pose = nullptr;
  Vec3 linear_velocity = Vec3::Zero(), angular_velocity = Vec3::Zero();
  double radius = 0.0;  // farthest point of the shape from the body origin
};

class PairContactCache {
 public:
  static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

  // The contact points of one entry, as built: each body's surface point in
  // its own frame (the anchors), and the normal in the frame of the body it
  // turns with.
  struct Point {
    Vec3 on_a, on_b, normal;
    double depth = 0.0, separation = 0.0, sphere_bound = 0.0;
    std::int32_t node_a = 0, node_b = 0;
    int level = 0;
    // The normal is a face axis of B's voxel boxes and not of A's: it turns
    // with B. Else with A (A's face, or a line of centres as built).
    bool normal_of_b = false;
    bool resolved = true;  // found at the leaves (an unresolved pair's frontier: false)
  };
  // A pair's contacts as built, and the pose of B in A's frame then.
  // Carried over unchanged while it is reused.
  struct Entry {
    std::uint64_t key = 0;  // entity ids a, b packed
    Vec3 b_in_a;            // B's origin in A's frame
    Quat a_to_b;            // conjugate(q_a) q_b: B's orientation in A's frame
    double tolerance = 0.0; // metres any point of one body may drift relative to the other
    SpherePair leaf;        // the test's deepest leaf pair then (PairTest::resumeColliding)
    int level = 0;
    std::uint32_t first = 0, count = 0;  // its points
  };
  // The entries a chunk of the pairs records while building its contacts;
  // joined in pair order by commit(). A cache line of its own: chunks are
  // filled side by side.
  struct alignas(64) Pending {
    std::vector<Entry> entries;
    std::vector<Point> points;
    void clear() {
      entries.clear();
      points.clear();
    }
    // Room for `entries` entries and `points` points.
    void reserve(std::size_t entries, std::size_t points);
  };

  PairContactCache();
  ~PairContactCache();
  PairContactCache(PairContactCache&&) noexcept;
  PairContactCache& operator=(PairContactCache&&) noexcept;

  // Ticks of the bodies' relative motion now that must still fit in the
  // tolerance. A pair at rest drifts to and fro and its old contacts are off
  // by the drift either way; one moving steadily (a ball rolling) would
  // always have them behind, a bias in one direction (a torque against the
  // roll), so it is built anew while it moves that fast. A ball rolling down
  // a slope against rolling resistance ends 1 s 4.6 % faster than theory at
  // 2 ticks, 6.3 % at 1 and 12 % at 0 (2.7 % built every tick; test_physics'
  // slope, reuse_tolerance 0.05; docs/response.md).
  static constexpr double kMotionTicks = 2.0;

  // Last tick's entry of the pair (a, b in this order) when no point of one
  // body has moved, relative to the other, by more than the entry's
  // tolerance since its contacts were built, nor would move so within
  // kMotionTicks ticks of dt at their velocities now; kNone otherwise. Read
  // only: safe from many threads at once.
  std::uint32_t find(const ReuseBody& a, const ReuseBody& b, double dt) const;
  const Entry& entry(std::uint32_t index) const { return entries_[index]; }

  // The entry's contacts at the bodies' poses now, appended to `out`, each
  // measured again from its anchors (as Box2D v3 measures its substeps'
  // separations): the surface points on A and on B where they are on their
  // bodies now, the normal turned with the body whose face it is (with A
  // when it is neither's nor B's alone), the separation between
  // the two points along it and the point halfway between them. So a
  // carried contact's separation is the bodies' now, to first order in
  // their drift, not the one it was built with (at least 0 for a point of
  // an unresolved pair, as when it was built). `base` gives the ids, dense
  // indices and priority.
  void place(std::uint32_t index, const Contact& base, const Pose& pose_a, const Pose& pose_b,
             std::vector<Contact>& out) const;

  // Into `pending`: the entry of a pair whose contacts [first, end) of
  // `contacts` were just built from its test (Colliding, or Unresolved for
  // the steady frontier: Physics), with its tolerance in metres.
  static void record(const PairTest& test, const ReuseBody& a, const ReuseBody& b, double tolerance,
                     const Contact* first, const Contact* end, Pending& pending);
  // ... or a reused entry, carried over as it is.
  void carry(std::uint32_t index, Pending& pending) const;
  // The next tick's cache: the pending entries of pending[0..count), in that
  // order. The entries found this tick are no longer valid after it.
  void commit(const Pending* const* pending, std::size_t count);
  void clear();
  // Room for a tick of `entries` entries and `points` points (both caches of
  // commit's swap, and the index), so such a tick allocates nothing.
  void reserve(std::size_t entries, std::size_t points);
  std::size_t size() const { return entries_.size(); }
  // What the next tick finds, for a saved world (CarriedState): the entries
  // (each's points [first, first + count) of points()), and the same put back
  // (keys as the loaded world's ids give them; checked by the caller).
  const std::vector<Entry>& entries() const { return entries_; }
  const std::vector<Point>& points() const { return points_; }
  void restore(const std::vector<Entry>& entries, const std::vector<Point>& points);

 private:
  std::vector<Entry> entries_, next_entries_;
  std::vector<Point> points_, next_points_;
  std::unique_ptr<detail::FlatHashMap> index_, next_index_;  // key -> entry
};

}  // namespace stc
