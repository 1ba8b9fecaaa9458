// The tick's figures the node reports, listed once. Each entry names a
// TickStats field and says how it comes from the World's TickReport `r`;
// tick_stats, the ~error_report CSV and the diagnostics' "tick report" status
// are all filled from this list. A new counter touches TickReport, one line
// here and one line of msg/TickStats.msg.
#pragma once

#include "sphere_tree_collision/world.hpp"

#include <sphere_tree_collision/TickStats.h>

#include <cstdint>

// X(field, value from r): in TickStats.msg's order.
#define STC_TICK_REPORT_FIELDS(X)                                                                                  \
  X(integrate_ms, (r.phases.integrate_s + r.phases.sweep_s) * 1e3) /* the swept test runs after the broad phase */ \
  X(sweep_ms, r.phases.sweep_s * 1e3)                                                                              \
  X(broad_ms, r.phases.broad_s * 1e3)                                                                              \
  X(narrow_ms, r.phases.narrow_s * 1e3)                                                                            \
  X(response_ms, r.phases.response_s * 1e3)                                                                        \
  X(contacts_ms, r.phases.contacts_s * 1e3)                                                                        \
  X(total_ms, r.phases.total_s * 1e3)                                                                              \
  X(scheduling_overhead_ms, r.detection.scheduling_overhead_s * 1e3)                                               \
  X(perception_used, r.accuracy.perception_used)                                                                   \
  X(entities, r.bodies.entities)                                                                                   \
  X(broad_pairs, r.detection.broad_pairs)                                                                          \
  X(colliding, r.detection.colliding)                                                                              \
  X(reused, r.detection.reused)                                                                                    \
  X(separate, r.detection.separate)                                                                                \
  X(unresolved, r.detection.unresolved)                                                                            \
  X(unresolved_accepted, r.detection.unresolved_accepted)                                                          \
  X(frontier_kept, r.response.frontier_kept)                                                                       \
  X(sphere_tests, r.detection.sphere_tests)                                                                        \
  X(interrupted, r.detection.interrupted)                                                                          \
  X(geometric_inaccuracy, r.accuracy.geometric_inaccuracy)                                                         \
  X(geometric_bound, r.accuracy.geometric_bound)                                                                   \
  X(perceived_inaccuracy, r.accuracy.perceived_inaccuracy)                                                         \
  X(contacts, r.response.contacts)                                                                                 \
  X(interior_contacts, r.response.interior_contacts)                                                               \
  X(tick_budget_ms, r.budget.tick_budget_s * 1e3)                                                                  \
  X(narrow_budget_ms, r.budget.narrow_budget_s * 1e3)                                                              \
  X(response_budget_ms, r.budget.response_budget_s * 1e3)                                                          \
  X(reserve_ms, r.budget.reserve_s * 1e3)                                                                          \
  X(velocity_passes, r.response.velocity_passes)                                                                   \
  X(position_passes, r.response.position_passes)                                                                   \
  X(quarantined, r.bodies.quarantined)                                                                             \
  X(left_world, r.bodies.left_world)                                                                               \
  X(sleeping, r.bodies.sleeping)                                                                                   \
  X(fractures, r.fracture.fractures)                                                                               \
  X(fractures_waiting, r.fracture.fractures_deferred)                                                              \
  X(piece_trees, r.fracture.piece_trees)                                                                           \
  X(fracture_ms, r.fracture.fracture_s * 1e3)                                                                      \
  X(islands_full, r.response.levels.islands_full)                                                                  \
  X(islands_held, r.response.levels.islands_held)                                                                  \
  X(bodies_held, r.response.levels.bodies_held)                                                                    \
  X(islands_joined, r.response.levels.islands_joined)

namespace stc_ros {

// The report's figures into their TickStats fields (the node's own fields,
// header, rejections, clock and the like, are left as they are).
void fillFromReport(const stc::TickReport& r, sphere_tree_collision::TickStats& s);

// visit(name, value) for each field of the list, read from `s`, in order.
template <typename Visit>
void forEachReportField(const sphere_tree_collision::TickStats& s, Visit&& visit) {
#define STC_VISIT_FIELD(field, value) visit(#field, s.field);
  STC_TICK_REPORT_FIELDS(STC_VISIT_FIELD)
#undef STC_VISIT_FIELD
}

}  // namespace stc_ros
