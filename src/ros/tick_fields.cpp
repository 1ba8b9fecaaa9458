#include "sphere_tree_collision/ros/tick_fields.hpp"

namespace stc_ros {

void fillFromReport(const stc::TickReport& r, sphere_tree_collision::TickStats& s) {
#define STC_FILL_FIELD(field, value) s.field = static_cast<decltype(s.field)>(value);
  STC_TICK_REPORT_FIELDS(STC_FILL_FIELD)
#undef STC_FILL_FIELD
}

}  // namespace stc_ros
