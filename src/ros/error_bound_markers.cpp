#include "sphere_tree_collision/ros/error_bound_markers.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/marker_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace stc_ros {
namespace {

using visualization_msgs::Marker;

const std::string kBoundsNs = "error_bounds", kTextNs = "error_text";
constexpr double kTextTowardCamera = 0.6;  // share of the way from the gaze point to the camera
constexpr float kBoundAlpha = 0.4f;  // see-through: the rocks and the contact dot inside stay visible

// Amber for a bound nobody looks at, red for the one the viewer would notice
// most (priority relative to the tick's largest): distinct from the green of
// resolved contacts and the magenta of the gaze.
std_msgs::ColorRGBA boundColor(double priority, double max_priority) {
  const float t = max_priority > 0.0 ? static_cast<float>(std::clamp(priority / max_priority, 0.0, 1.0)) : 0.0f;
  return toColorMsg(1.0f, 0.78f - 0.6f * t, 0.1f, kBoundAlpha);
}

}  // namespace

void ErrorBoundMarkers::build(const stc::World& world, const stc::TickReport& report,
                              const std::optional<stc::Vec3>& gaze_point, const ros::Time& stamp,
                              const ErrorBoundOptions& options, visualization_msgs::MarkerArray& out) {
  const auto& contacts = world.contacts();
  double max_priority = 0.0;
  for (const stc::Contact& c : contacts) {
    if (!c.resolved) max_priority = std::max(max_priority, c.priority);
  }
  std::size_t used = 0;
  const auto add = [&](const std::string& ns, int id, int type, int action) -> Marker& {
    Marker& m = appendMarker(out, used, ns, id, type, stamp, options.frame);
    m.action = action;
    return m;
  };

  // A pair's contacts are consecutive in world.contacts() and share its bound.
  std::size_t bounds = 0;
  stc::Vec3 centroid = stc::Vec3::Zero();
  for (std::size_t i = 0; i < contacts.size() && bounds < options.max_bounds;) {
    const stc::Contact& first = contacts[i];
    std::size_t end = i + 1;
    while (end < contacts.size() && contacts[end].index_a == first.index_a && contacts[end].index_b == first.index_b) {
      ++end;
    }
    if (!first.resolved && first.point.allFinite() && std::isfinite(first.gap_bound)) {
      stc::Vec3 point = stc::Vec3::Zero();
      for (std::size_t k = i; k < end; ++k) point += contacts[k].point;
      point /= static_cast<double>(end - i);
      Marker& m = add(kBoundsNs, static_cast<int>(bounds), Marker::SPHERE, Marker::ADD);
      m.pose.position = toPointMsg(point);
      m.scale.x = m.scale.y = m.scale.z = 2.0 * first.gap_bound;  // radius h_a + h_b
      m.color = boundColor(first.priority, max_priority);
      centroid += point;
      ++bounds;
    }
    i = end;
  }
  for (std::size_t k = bounds; k < drawn_; ++k) add(kBoundsNs, static_cast<int>(k), Marker::SPHERE, Marker::DELETE);
  drawn_ = bounds;

  if (gaze_point && gaze_point->allFinite()) {
    text_anchor_ = *gaze_point;
  } else if (bounds > 0) {
    text_anchor_ = centroid / static_cast<double>(bounds);
  }
  Marker& text = add(kTextNs, 0, Marker::TEXT_VIEW_FACING, Marker::ADD);
  // nabla is the paper's estimate (distance between the last intersecting
  // centres), not bounded by the bound sum: both are shown, with what they are.
  char line[200];
  std::snprintf(line, sizeof line,
                "%zu of %zu pairs accepted unresolved\nbound sum (h_a+h_b) %.3f m\nnabla %.3f m   P %.3f",
                report.detection.unresolved_accepted, report.detection.broad_pairs, report.accuracy.geometric_bound,
                report.accuracy.geometric_inaccuracy, report.accuracy.perceived_inaccuracy);
  text.text = line;
  text.color = toColorMsg(1.0f, 1.0f, 1.0f, 0.95f);
  const stc::Perception& perception = world.perception();
  const stc::Pose& camera = perception.camera().camera_to_world;
  // Most of the way from the gaze point to the camera (its size on screen does
  // not depend on it): in front of the rocks around the gaze and above the
  // walls beside it. A quarter of the way, the demo's ravine walls and the
  // rocks in front of the gaze cut into the text.
  const stc::Vec3 at = text_anchor_ + kTextTowardCamera * (camera.position - text_anchor_);
  const double height = std::max(options.text_height_per_metre * (camera.position - at).norm(), 1e-3);
  text.scale.z = height;
  stc::Vec3 local = camera.orientation.conjugate() * (at - camera.position);
  // Three lines centred on the pose: lifted up the image (optical -y) so the
  // lowest clears the gaze dot however steeply the camera looks down.
  local.y() -= 3.0 * height;
  // Kept inside the middle 70 % of the camera's image (optical frame: x right,
  // y down, z ahead), so a gaze near an edge does not push half the text off
  // screen, also in a viewer with a narrower window (rviz beside its panels).
  const double half_width = 0.28 * std::strlen("000 of 0000 pairs accepted unresolved") * height;
  const double half_height = 1.8 * height;
  const double tan_x = 0.7 * 0.5 * perception.camera().width / perception.focalPx();
  const double tan_y = 0.7 * 0.5 * perception.camera().height / perception.focalPx();
  if (local.z() > 0.0) {
    const double max_x = std::max(local.z() * tan_x - half_width, 0.0);
    const double max_y = std::max(local.z() * tan_y - half_height, 0.0);
    local.x() = std::clamp(local.x(), -max_x, max_x);
    local.y() = std::clamp(local.y(), -max_y, max_y);
  }
  text.pose.position = toPointMsg(camera.position + camera.orientation * local);
  out.markers.resize(used);
}

}  // namespace stc_ros
