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
#define STC_TICK_REPORT_FIELDS(X)                                                                       \
  X(integrate_ms, (r.integrate_s + r.sweep_s) * 1e3) /* the swept test runs after the broad phase */     \
  X(sweep_ms, r.sweep_s * 1e3)                                                                           \
  X(broad_ms, r.broad_s * 1e3)                                                                           \
  X(narrow_ms, r.narrow_s * 1e3)                                                                         \
  X(response_ms, r.response_s * 1e3)                                                                     \
  X(contacts_ms, r.contacts_s * 1e3)                                                                     \
  X(total_ms, r.total_s * 1e3)                                                                           \
  X(scheduling_overhead_ms, r.scheduling_overhead_s * 1e3)                                               \
  X(perception_used, r.perception_used)                                                                  \
  X(entities, r.entities)                                                                                \
  X(broad_pairs, r.broad_pairs)                                                                          \
  X(colliding, r.colliding)                                                                              \
  X(reused, r.reused)                                                                                    \
  X(separate, r.separate)                                                                                \
  X(unresolved, r.unresolved)                                                                            \
  X(unresolved_accepted, r.unresolved_accepted)                                                          \
  X(frontier_kept, r.frontier_kept)                                                                      \
  X(sphere_tests, r.sphere_tests)                                                                        \
  X(interrupted, r.interrupted)                                                                          \
  X(geometric_inaccuracy, r.geometric_inaccuracy)                                                        \
  X(geometric_bound, r.geometric_bound)                                                                  \
  X(perceived_inaccuracy, r.perceived_inaccuracy)                                                        \
  X(contacts, r.contacts)                                                                                \
  X(tick_budget_ms, r.tick_budget_s * 1e3)                                                               \
  X(narrow_budget_ms, r.narrow_budget_s * 1e3)                                                           \
  X(response_budget_ms, r.response_budget_s * 1e3)                                                       \
  X(reserve_ms, r.reserve_s * 1e3)                                                                       \
  X(velocity_passes, r.velocity_passes)                                                                  \
  X(position_passes, r.position_passes)                                                                  \
  X(quarantined, r.quarantined)                                                                          \
  X(left_world, r.left_world)                                                                            \
  X(sleeping, r.sleeping)                                                                                \
  X(fractures, r.fractures)                                                                              \
  X(fractures_waiting, r.fractures_deferred)                                                             \
  X(piece_trees, r.piece_trees)                                                                          \
  X(fracture_ms, r.fracture_s * 1e3)

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
