// Shared by the libFuzzer targets: values chosen the way a hostile or buggy
// publisher would send them, a small world, and the invariants every target
// checks. A check that fails aborts: libFuzzer saves the input as a finding.
#pragma once

#include "sphere_tree_collision/world.hpp"
#include "sweep_and_prune.hpp"
#include "world_access.hpp"

#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <set>
#include <utility>

namespace stc_fuzz {

inline void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz invariant violated: %s\n", what);
  std::abort();
}

// Edge values first (what breaks arithmetic), then plain bytes, then a
// moderate value in [lo, hi] (what reaches the deep code paths).
inline double pickDouble(FuzzedDataProvider& in, double lo, double hi) {
  static const double kEdges[] = {0.0, -0.0, 1.0, -1.0, 5e-324, 1e-310, DBL_MIN, 1e-300, 1e-9,
                                  1e300, -1e300, 1e308, DBL_MAX, -DBL_MAX,
                                  std::numeric_limits<double>::infinity(),
                                  -std::numeric_limits<double>::infinity(),
                                  std::numeric_limits<double>::quiet_NaN(), 1e3, 1e4, 1.0001e4, -1e6};
  switch (in.ConsumeIntegralInRange<int>(0, 7)) {
    case 0: return kEdges[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kEdges) - 1)];
    case 1: return in.ConsumeFloatingPoint<double>();
    default: return lo + (hi - lo) * in.ConsumeProbability<double>();
  }
}

inline stc::Vec3 pickVec3(FuzzedDataProvider& in, double lo, double hi) {
  const double x = pickDouble(in, lo, hi);
  const double y = pickDouble(in, lo, hi);
  const double z = pickDouble(in, lo, hi);
  return {x, y, z};
}

// Mostly unit quaternions (random axis-angle), sometimes raw values.
inline stc::Quat pickOrientation(FuzzedDataProvider& in) {
  if (in.ConsumeIntegralInRange<int>(0, 3) == 0) {
    const double x = pickDouble(in, -1, 1), y = pickDouble(in, -1, 1), z = pickDouble(in, -1, 1);
    return stc::Quat(pickDouble(in, -1, 1), x, y, z);
  }
  stc::Vec3 axis = pickVec3(in, -1, 1);
  if (!axis.allFinite() || axis.norm() < 1e-6) axis = stc::Vec3::UnitZ();
  return stc::Quat(Eigen::AngleAxisd(pickDouble(in, -4, 4), axis.normalized())).normalized();
}

// Small enough that one input runs in milliseconds: grids up to 32^3, 48 entities.
inline stc::WorldConfig smallWorldConfig() {
  stc::WorldConfig config;
  config.voxel_limits.max_voxels = 32 * 32 * 32;
  config.max_entities = 48;
  return config;
}

// After a step: every body within the limits (quarantine removed the rest),
// every contact finite, and the broad phase's pairs exactly the overlapping
// boxes it holds (brute force over all pairs).
inline void checkWorldAfterStep(const stc::World& world, const stc::TickReport& report) {
  for (const stc::BodyState& body : world.bodies()) {
    require(body.is_static || stc::quarantineReason(body, world.config().limits) == stc::Quarantine::None,
            "a body beyond the limits survived the tick");
    require(body.pose.position.allFinite() && body.pose.orientation.coeffs().allFinite(), "non-finite pose");
  }
  for (const stc::Contact& c : world.contacts()) {
    require(c.point.allFinite() && c.normal.allFinite() && std::isfinite(c.depth), "non-finite contact");
  }
  require(report.bodies.entities == world.entityCount(), "report.bodies.entities differs from entityCount()");

  std::set<stc::EntityId> removed;
  for (const stc::QuarantinedEntity& q : world.quarantined()) {
    removed.insert(q.id);
    require(!world.indexOf(q.id).has_value(), "a quarantined entity is still in the world");
  }
  const stc::SweepAndPrune& broad = broadPhase(world);
  std::set<std::pair<stc::EntityId, stc::EntityId>> got, want;
  for (const stc::BroadPair& p : broad.pairs()) {
    require(p.first < p.second, "broad pair not ordered");
    if (removed.count(p.first) || removed.count(p.second)) continue;  // removed after the broad phase
    require(got.insert({p.first, p.second}).second, "broad pair reported twice");
  }
  const auto& ids = world.entityIds();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const stc::Aabb a = broad.box(ids[i]);
    for (std::size_t j = i + 1; j < ids.size(); ++j) {
      if (a.overlaps(broad.box(ids[j]))) want.insert(std::minmax(ids[i], ids[j]));
    }
  }
  require(got == want, "broad-phase pairs differ from brute force");
}

}  // namespace stc_fuzz
