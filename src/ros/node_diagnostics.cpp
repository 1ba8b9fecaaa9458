#include "sphere_tree_collision/ros/node_diagnostics.hpp"

#include "sphere_tree_collision/ros/tick_fields.hpp"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <cmath>

namespace stc_ros {
namespace {

using diagnostic_msgs::DiagnosticStatus;
using Status = diagnostic_updater::DiagnosticStatusWrapper;

// Below this share of ~rate the node is falling behind its timer.
constexpr double kSlowShare = 0.9;
// From this share of ~max_entities on, spawns will soon be refused.
constexpr double kFullShare = 0.9;

// OK while nothing of `what` happened since the last report; else WARN with
// how many and the latest.
void summariseSinceLastReport(Status& status, std::uint64_t count, const char* what, const std::string& latest) {
  if (count == 0) {
    status.summaryf(DiagnosticStatus::OK, "no %s since the last report", what);
  } else {
    status.summaryf(DiagnosticStatus::WARN, "%llu %s since the last report: %s", static_cast<unsigned long long>(count),
                    what, latest.c_str());
  }
}

}  // namespace

NodeDiagnostics::NodeDiagnostics(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const NodeParams& params)
    : rate_hz_(params.rate),
      tick_budget_param_ms_(params.tick_budget_ms),
      max_entities_(params.world.max_entities),
      updater_(nh, private_nh) {
  updater_.setHardwareID("none");  // software only
  updater_.add("tick rate", this, &NodeDiagnostics::tickRate);
  updater_.add("tick budget", this, &NodeDiagnostics::tickBudget);
  updater_.add("rejected inputs", this, &NodeDiagnostics::rejectedInputs);
  updater_.add("entities", this, &NodeDiagnostics::entities);
  updater_.add("quarantined bodies", this, &NodeDiagnostics::quarantined);
  updater_.add("tick report", this, &NodeDiagnostics::tickReport);
}

// What "over budget" means for a tick: the budget its step was given, else 1/~rate.
double NodeDiagnostics::budgetMs(const sphere_tree_collision::TickStats& stats) const {
  return std::isfinite(stats.tick_budget_ms) ? stats.tick_budget_ms : 1e3 / rate_hz_;
}

void NodeDiagnostics::onTick(const sphere_tree_collision::TickStats& stats) {
  if (stats.total_ms > budgetMs(stats)) ++over_budget_;
  last_ = stats;
  if (reported_stamp_.isZero()) {
    reported_stamp_ = stats.header.stamp;
    reported_tick_ = stats.tick;
  }
  updater_.update();  // publishes once per ~diagnostic_period
}

void NodeDiagnostics::tickRate(Status& status) {
  const double seconds = (last_.header.stamp - reported_stamp_).toSec();
  const std::uint64_t ticks = last_.tick - reported_tick_;
  const double rate = seconds > 0.0 ? ticks / seconds : 0.0;
  status.add("ticks per second (tick stamps)", rate);
  status.add("~rate", rate_hz_);
  status.add("ticks since the last report", ticks);
  status.add("tick", last_.tick);
  if (ticks == 0) {
    status.summary(DiagnosticStatus::WARN, "no tick since the last report");
  } else if (rate < kSlowShare * rate_hz_) {
    status.summaryf(DiagnosticStatus::WARN, "%.1f Hz, below ~rate %.1f Hz: ticks take longer than 1/~rate", rate, rate_hz_);
  } else {
    status.summaryf(DiagnosticStatus::OK, "%.1f Hz (~rate %.1f Hz)", rate, rate_hz_);
  }
  reported_tick_ = last_.tick;
  reported_stamp_ = last_.header.stamp;
}

void NodeDiagnostics::tickBudget(Status& status) {
  const std::uint64_t recent = over_budget_ - reported_over_budget_;
  status.add("ticks over budget", over_budget_);
  status.add("ticks over budget since the last report", recent);
  status.add("budget ms", budgetMs(last_));
  status.add("budget from", tick_budget_param_ms_ > 0.0    ? "~tick_budget"
                            : tick_budget_param_ms_ == 0.0 ? "1/~rate less publishing (~tick_budget 0)"
                                                           : "1/~rate: no tick budget (~tick_budget -1)");
  status.add("publishing ms", last_.publish_ms);
  status.add("last tick ms", last_.total_ms);
  summariseSinceLastReport(status, recent, "ticks over budget", std::to_string(last_.total_ms) + " ms last");
  reported_over_budget_ = over_budget_;
}

void NodeDiagnostics::rejectedInputs(Status& status) {
  const std::uint64_t recent = last_.rejected_inputs - reported_rejected_;
  status.add("rejected inputs", last_.rejected_inputs);
  status.add("spawn", last_.rejected_spawn);
  status.add("despawn", last_.rejected_despawn);
  status.add("gaze", last_.rejected_gaze);
  status.add("clicked_point", last_.rejected_clicked_point);
  status.add("last rejection", last_.last_rejection);
  summariseSinceLastReport(status, recent, "inputs rejected", last_.last_rejection);
  reported_rejected_ = last_.rejected_inputs;
}

void NodeDiagnostics::entities(Status& status) {
  status.add("entities", last_.entities);
  status.add("~max_entities", max_entities_);
  if (last_.entities >= max_entities_) {
    status.summary(DiagnosticStatus::ERROR, "at ~max_entities: spawns are refused");
  } else if (last_.entities >= kFullShare * max_entities_) {
    status.summaryf(DiagnosticStatus::WARN, "%u of %zu entities", last_.entities, max_entities_);
  } else {
    status.summaryf(DiagnosticStatus::OK, "%u of %zu entities", last_.entities, max_entities_);
  }
}

void NodeDiagnostics::quarantined(Status& status) {
  const std::uint64_t recent = last_.quarantined_total - reported_quarantined_;
  status.add("quarantined (total)", last_.quarantined_total);
  status.add("left the world (total)", last_.left_world_total);
  status.add("last removal", last_.last_quarantine);
  summariseSinceLastReport(status, recent, "bodies quarantined", last_.last_quarantine);
  reported_quarantined_ = last_.quarantined_total;
}

void NodeDiagnostics::tickReport(Status& status) {
  // uint8 flags as numbers, not characters.
  forEachReportField(last_, [&](const char* name, const auto& value) { status.add(name, +value); });
  status.summaryf(DiagnosticStatus::OK, "tick %llu", static_cast<unsigned long long>(last_.tick));
}

}  // namespace stc_ros
