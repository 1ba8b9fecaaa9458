// Perception: the paper's model of how noticeable a collision artefact is
// (2.3, 3.4.2). A pinhole camera, a fixation point F in pixels, and
// f(e, g) = g / exp(e / 100) with e and g in pixels.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <cmath>
#include <optional>

namespace stc {

using Vec2 = Eigen::Vector2d;

class PairTest;  // src/core/pair_test.hpp: what measure() and projectedGap() read

// Pinhole camera. The camera frame is the optical frame: x right, y down,
// z forward (REP 103 "_optical" convention). Pixel (0,0) is the top-left.
struct Camera {
  Pose camera_to_world;
  int width = 1280;
  int height = 720;
  double fov_y_deg = 60.0;  // vertical field of view
};
// A half-line in the world frame: origin + t * direction for t >= 0, direction unit.
struct Ray {
  Vec3 origin = Vec3::Zero();
  Vec3 direction = Vec3::UnitZ();
};

// Throws InputError naming "width", "height", "fov_y_deg", or "camera_pose"
// (not finite, a coordinate beyond 1e9 m, not a unit quaternion).
void validateCamera(const Camera& camera);

// Optical-frame pose of a camera at `eye` looking at `target`, image "up"
// towards `up` (world). Throws InputError("target") when target == eye; an
// `up` parallel to the view direction is replaced by another world axis.
Pose opticalLookAt(const Vec3& eye, const Vec3& target, const Vec3& up = Vec3::UnitZ());

// Perceived inaccuracy of one gap: g / exp(e / 100).
inline double perceivedInaccuracy(double eccentricity_px, double gap_px);

struct PairPerception {
  double eccentricity_px = 0.0;  // |proj(centre of collision) - F|
  double gap_estimate_px = 0.0;  // |proj(cA) - proj(cB)| of the last intersecting centres
  double gap_bound_px = 0.0;     // (h_a + h_b) projected at the centre of collision's depth
  double priority = 0.0;         // f(e, gap_estimate_px)
  double px_per_metre = 0.0;     // focal / depth of the centre of collision (0 behind the camera)
  bool visible = true;           // false: behind the camera or off screen (rule below)
};

// Rule for what the viewer cannot see:
// - centre of collision behind (or on) the camera plane (depth <= kNearDepth):
//   visible = false, eccentricity = +inf, gaps 0, priority 0;
// - in front but projecting outside [0,width]x[0,height]: visible = false,
//   e measured to the off-screen pixel and priority = f(e, g) as usual (the
//   bodies have extent, so their gap may still show; f decays fast with e and
//   stays continuous across the border).
// The World still accepts or rejects unresolved pairs per its policy.

class Perception {
 public:
  void setCamera(const Camera& camera);  // validates
  const Camera& camera() const { return camera_; }
  // Throws InputError("fixation") for non-finite values. Off-screen fixations
  // are rejected too (InputError "fixation"): the viewer looks at the screen.
  void setFixation(const Vec2& pixel);
  void clearFixation() { fixation_.reset(); }
  bool hasFixation() const { return fixation_.has_value(); }
  const std::optional<Vec2>& fixation() const { return fixation_; }

  static constexpr double kNearDepth = 1e-6;  // metres; nearer points do not project

  // Pixel of a world point; nullopt when it is behind (or on) the camera plane
  // or so far out that its pixel is not finite.
  std::optional<Vec2> project(const Vec3& world) const;
  // The inverse of project: the viewing ray through a pixel (any pixel, on the
  // image or not), from the camera centre; and the world point of a pixel at a
  // depth along the optical axis (project(unproject(p, d)) == p for d > kNearDepth).
  Ray rayThrough(const Vec2& pixel) const;
  Vec3 unproject(const Vec2& pixel, double depth) const;
  // Depth along the optical axis; nullopt when <= kNearDepth.
  std::optional<double> depthOf(const Vec3& world) const;
  // Pixels per metre at unit depth: a length d at depth z spans d * focalPx() / z pixels.
  double focalPx() const { return focal_px_; }
  bool onScreen(const Vec2& pixel) const;
  // Without a fixation every pair is reported invisible with priority 0.
  PairPerception measure(const PairTest& test) const;
  // What f(e, g) needs of a point besides g, for schedulers that re-measure g
  // often: weight = exp(-e / 100) with e the point's eccentricity, and the
  // pixels per metre at its depth, and its pixel. All 0 behind the camera or
  // without a fixation.
  struct GazeWeight {
    double weight = 0.0;
    double px_per_metre = 0.0;
    Vec2 pixel = Vec2::Zero();
  };
  GazeWeight gazeWeight(const Vec3& world) const;
  // gazeWeight without the weight (left 0): the pixel and the pixels per
  // metre. Inline and with no library call, for a loop over many points.
  GazeWeight pixelAndScale(const Vec3& world) const {
    GazeWeight out;
    const Vec3 c = world_to_camera_rotation_ * (world - camera_position_);
    if (!(c.z() > kNearDepth) || !fixation_) return out;
    out.px_per_metre = focal_px_ / c.z();
    out.pixel = Vec2(0.5 * camera_.width + out.px_per_metre * c.x(), 0.5 * camera_.height + out.px_per_metre * c.y());
    return out;
  }
  // The paper's on-screen gap estimate alone: |proj(cA) - proj(cB)| of the
  // last intersecting centres; when either is behind the camera, the 3D gap
  // estimate times `px_per_metre`. What a scheduler re-measures after a step.
  double projectedGap(const PairTest& test, double px_per_metre) const;

 private:
  Camera camera_;
  Mat3 world_to_camera_rotation_ = Mat3::Identity();
  Vec3 camera_position_ = Vec3::Zero();
  double focal_px_ = 0.5 * 720 / 0.57735026918962573;  // default Camera: 720 px, 60 deg
  std::optional<Vec2> fixation_;
};

inline double perceivedInaccuracy(double eccentricity_px, double gap_px) {
  return gap_px / std::exp(eccentricity_px / 100.0);
}

}  // namespace stc
