// ErrorReport: `~error_report`, a CSV file with one row per tick: the stamp,
// the tick, the budget and scheduler it ran under, every figure of the tick's
// report (tick_fields.hpp: the same names and values as tick_stats; among
// them the pairs left unresolved, nabla, the bound sum and P), and the gaze.
// A user measures their own scene and gaze stream with it, and
// bench/plot_node_error_report.py plots it. Rows are line-buffered: a row is
// in the file once its tick is over, also when the node is killed.
#pragma once

#include "sphere_tree_collision/perception.hpp"

#include <sphere_tree_collision/TickStats.h>

#include <cstdio>
#include <optional>
#include <string>

namespace stc_ros {

class ErrorReport {
 public:
  // The CSV's columns, in order (the header row).
  static std::string header();

  // Creates (truncates) `path` and writes the header. Throws
  // stc::InputError("error_report", why) when it cannot.
  explicit ErrorReport(const std::string& path);
  ~ErrorReport();
  ErrorReport(const ErrorReport&) = delete;
  ErrorReport& operator=(const ErrorReport&) = delete;

  // One row of the tick `stats` describes (budgets without a limit as they
  // are there: -1); no gaze as empty x, y.
  void write(const sphere_tree_collision::TickStats& stats, const std::optional<stc::Vec2>& gaze);

 private:
  std::FILE* file_ = nullptr;
};

}  // namespace stc_ros
