#include "sphere_tree_collision/ros/error_report.hpp"

#include "sphere_tree_collision/types.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

namespace stc_ros {

const char* const ErrorReport::kHeader =
    "stamp,tick,budget_ms,budget_sphere_tests,scheduler,broad_pairs,unresolved,unresolved_accepted,"
    "nabla_m,bound_sum_m,perceived,narrow_ms,sphere_tests,gaze_x,gaze_y";

ErrorReport::ErrorReport(const std::string& path) {
  if (path.empty()) throw stc::InputError("error_report", "is empty (leave it unset for no report)");
  file_ = std::fopen(path.c_str(), "w");
  if (!file_) throw stc::InputError("error_report", "cannot write '" + path + "': " + std::strerror(errno));
  std::setvbuf(file_, nullptr, _IOLBF, 0);
  std::fprintf(file_, "%s\n", kHeader);
}

ErrorReport::~ErrorReport() {
  if (file_) std::fclose(file_);
}

void ErrorReport::write(const ros::Time& stamp, std::uint64_t tick, const stc::TickReport& r, const stc::Budget& budget,
                        const char* scheduler, const std::optional<stc::Vec2>& gaze) {
  const double budget_ms = std::isfinite(budget.seconds) ? budget.seconds * 1e3 : -1.0;
  const long long sphere_tests =
      budget.sphere_tests == std::numeric_limits<std::int64_t>::max() ? -1 : static_cast<long long>(budget.sphere_tests);
  // %.17g: every double reads back exactly (a test compares rows with tick_stats).
  std::fprintf(file_, "%u.%09u,%llu,%.17g,%lld,%s,%zu,%zu,%zu,%.17g,%.17g,%.17g,%.17g,%lld,", stamp.sec, stamp.nsec,
               static_cast<unsigned long long>(tick), budget_ms, sphere_tests, scheduler, r.broad_pairs, r.unresolved,
               r.unresolved_accepted, r.geometric_inaccuracy, r.geometric_bound, r.perceived_inaccuracy,
               r.narrow_s * 1e3, static_cast<long long>(r.sphere_tests));
  if (gaze) {
    std::fprintf(file_, "%.17g,%.17g\n", gaze->x(), gaze->y());
  } else {
    std::fputs(",\n", file_);
  }
}

}  // namespace stc_ros
