// ErrorBoundMarkers: the paper's error bound drawn as it happens. Every pair
// the budget left unresolved and the policy accepted as colliding is a
// translucent sphere of radius h_a + h_b at its contact point (the mean of the
// pair's contact points): the two surfaces are at most that far apart, so the
// accepted contact is wrong by no more than the sphere shows. Warmer = higher
// perceptual priority (the viewer would notice it more). A text facing the
// viewer near the gaze point gives the tick's nabla, bound sum and P.
// Namespaces: `error_bounds` (SPHERE per pair, ids 0..n-1), `error_text`.
#pragma once

#include "sphere_tree_collision/world.hpp"

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include <optional>
#include <string>

namespace stc_ros {

struct ErrorBoundOptions {
  std::string frame = "world";
  std::size_t max_bounds = 2000;  // spheres drawn at most (the text still counts every pair)
  // Text height as a share of its distance from the perception camera: the
  // same size on screen whether the gaze rests near or far.
  double text_height_per_metre = 0.03;
};

class ErrorBoundMarkers {
 public:
  // One array for one tick: a sphere per accepted unresolved pair in
  // world.contacts(), DELETEs for the spheres of the previous array beyond
  // them, and the text above `gaze_point`, most of the way to the
  // camera (without a gaze: the bounds' centroid, else where it was).
  void build(const stc::World& world, const stc::TickReport& report, const std::optional<stc::Vec3>& gaze_point,
             const ros::Time& stamp, const ErrorBoundOptions& options, visualization_msgs::MarkerArray& out);
  // Nobody subscribed any more: a new subscriber has nothing to delete.
  void forget() { drawn_ = 0; }

 private:
  std::size_t drawn_ = 0;
  stc::Vec3 text_anchor_ = stc::Vec3(0.0, 0.0, 1.0);
};

}  // namespace stc_ros
