// ErrorReport: `~error_report`, a CSV file with one row per tick of what the
// tick's approximation cost: the budget and scheduler it ran under, how many
// broad-phase pairs it left unresolved, nabla, the bound sum and P, and the
// gaze. A user measures their own scene and gaze stream with it, and
// bench/plot_node_error_report.py plots it. Rows are line-buffered: a row is
// in the file once its tick is over, also when the node is killed.
#pragma once

#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/world.hpp"

#include <ros/time.h>

#include <cstdio>
#include <optional>
#include <string>

namespace stc_ros {

class ErrorReport {
 public:
  // The CSV's columns, in order (the header row).
  static const char* const kHeader;

  // Creates (truncates) `path` and writes the header. Throws
  // stc::InputError("error_report", why) when it cannot.
  explicit ErrorReport(const std::string& path);
  ~ErrorReport();
  ErrorReport(const ErrorReport&) = delete;
  ErrorReport& operator=(const ErrorReport&) = delete;

  // One row. A budget without a limit is written as -1; no gaze as empty x, y.
  void write(const ros::Time& stamp, std::uint64_t tick, const stc::TickReport& report, const stc::Budget& budget,
             const char* scheduler, const std::optional<stc::Vec2>& gaze);

 private:
  std::FILE* file_ = nullptr;
};

}  // namespace stc_ros
