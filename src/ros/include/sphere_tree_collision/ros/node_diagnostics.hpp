// NodeDiagnostics: the world node's health on /diagnostics (diagnostic_updater),
// one status per concern, each named "<node>: <concern>":
//   tick rate          ticks per second judged from tick stamps, against ~rate
//   tick budget        steps longer than the budget they were given (without one: than 1/~rate),
//                      where that budget came from, and the node's publishing a tick
//   rejected inputs    bad messages, total and per input topic
//   entities           entity count against ~max_entities
//   quarantined bodies bodies removed for leaving the physical limits or the world
// Fed the tick's TickStats (the node's one record of its counters) every tick;
// the updater publishes every ~diagnostic_period (1 s by default).
#pragma once

#include "sphere_tree_collision/ros/node_params.hpp"

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sphere_tree_collision/TickStats.h>

#include <cstdint>

namespace stc_ros {

class NodeDiagnostics {
 public:
  NodeDiagnostics(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const NodeParams& params);

  // After each tick, with what tick_stats carries for it.
  void onTick(const sphere_tree_collision::TickStats& stats);
  // Live tuning: ~tick_budget may change.
  void retune(const NodeParams& params) { tick_budget_param_ms_ = params.tick_budget_ms; }

 private:
  double budgetMs(const sphere_tree_collision::TickStats& stats) const;
  void tickRate(diagnostic_updater::DiagnosticStatusWrapper& status);
  void tickBudget(diagnostic_updater::DiagnosticStatusWrapper& status);
  void rejectedInputs(diagnostic_updater::DiagnosticStatusWrapper& status);
  void entities(diagnostic_updater::DiagnosticStatusWrapper& status);
  void quarantined(diagnostic_updater::DiagnosticStatusWrapper& status);
  // Every figure of the latest tick's report, by its tick_stats name (tick_fields.hpp).
  void tickReport(diagnostic_updater::DiagnosticStatusWrapper& status);

  double rate_hz_;
  double tick_budget_param_ms_;  // ~tick_budget: > 0, 0 (1/~rate less publishing) or -1 (none)
  std::size_t max_entities_;
  sphere_tree_collision::TickStats last_;  // the latest tick
  std::uint64_t over_budget_ = 0;
  // At the previous report: what the window since then is measured against.
  std::uint64_t reported_tick_ = 0;
  ros::Time reported_stamp_;
  std::uint64_t reported_over_budget_ = 0, reported_rejected_ = 0, reported_quarantined_ = 0;
  diagnostic_updater::Updater updater_;
};

}  // namespace stc_ros
