#include "sphere_tree_collision/ros/error_report.hpp"

#include "sphere_tree_collision/ros/tick_fields.hpp"
#include "sphere_tree_collision/types.hpp"

#include <cerrno>
#include <cstring>
#include <type_traits>

namespace stc_ros {
namespace {

// One cell and its comma. %.17g: every double reads back exactly (a test
// compares rows with tick_stats); a flag (uint8 in a message) as 0 or 1.
template <typename T>
void writeCell(std::FILE* file, const T& value) {
  if constexpr (std::is_floating_point_v<T>) {
    std::fprintf(file, "%.17g,", static_cast<double>(value));
  } else if constexpr (std::is_signed_v<T>) {
    std::fprintf(file, "%lld,", static_cast<long long>(value));
  } else {
    std::fprintf(file, "%llu,", static_cast<unsigned long long>(value));
  }
}

}  // namespace

std::string ErrorReport::header() {
  std::string columns = "stamp,tick,budget_ms,budget_sphere_tests,scheduler,";
  forEachReportField(sphere_tree_collision::TickStats{}, [&](const char* name, const auto&) {
    columns += name;
    columns += ',';
  });
  return columns + "gaze_x,gaze_y";
}

ErrorReport::ErrorReport(const std::string& path) {
  if (path.empty()) throw stc::InputError("error_report", "is empty (leave it unset for no report)");
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) throw stc::InputError("error_report", "cannot write '" + path + "': " + std::strerror(errno));
  std::setvbuf(file_, nullptr, _IOLBF, 0);
  std::fprintf(file_, "%s\n", header().c_str());
}

ErrorReport::~ErrorReport() {
  if (file_) std::fclose(file_);
}

void ErrorReport::write(const sphere_tree_collision::TickStats& s, const std::optional<stc::Vec2>& gaze) {
  std::fprintf(file_, "%u.%09u,", s.header.stamp.sec, s.header.stamp.nsec);
  writeCell(file_, s.tick);
  writeCell(file_, s.budget_ms);
  writeCell(file_, s.budget_sphere_tests);
  std::fprintf(file_, "%s,", s.scheduler.c_str());
  forEachReportField(s, [&](const char*, const auto& value) { writeCell(file_, value); });
  if (gaze) {
    std::fprintf(file_, "%.17g,%.17g\n", gaze->x(), gaze->y());
  } else {
    std::fputs(",\n", file_);
  }
}

}  // namespace stc_ros
