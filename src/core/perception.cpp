// Perception: pinhole projection and the paper's f(e, g) for one PairTest.
//
// Rule for points the viewer cannot see (tested in test_perception.cpp):
// - Centre of collision behind (or on) the camera plane (depth <= kNearDepth):
//   no pixel exists. visible = false, eccentricity = +inf, gaps = 0,
//   priority = 0: the viewer cannot see anything of it this frame.
// - Centre of collision in front but outside the image [0,w]x[0,h]:
//   visible = false, but e is measured to the off-screen pixel and the
//   priority is f(e, g) as usual. Why: the centre is a point while the two
//   bodies and their gap have extent, so a pair just past the border can still
//   show its gap on screen; f decays as exp(-e/100), so the priority falls
//   fast with the distance past the border and stays continuous across it
//   (no ordering jump when a pair drifts out of view).
// Either way the World still accepts or rejects unresolved pairs per its policy.
#include "sphere_tree_collision/perception.hpp"

#include "pair_test.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace stc {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxImageSide = 1 << 16;        // pixels; larger is a unit mistake
constexpr double kOrientationNormTol = 1e-3;  // |q| may be off by this much, then normalised
// Metres from the origin: farther, projections of the scene overflow (found by fuzz_gaze).
constexpr double kMaxCameraCoordinate = 1e9;

}  // namespace

void validateCamera(const Camera& camera) {
  if (camera.width <= 0 || camera.width > kMaxImageSide) {
    throw InputError("width", "must be in [1, " + std::to_string(kMaxImageSide) + "] pixels, got " +
                                  std::to_string(camera.width));
  }
  if (camera.height <= 0 || camera.height > kMaxImageSide) {
    throw InputError("height", "must be in [1, " + std::to_string(kMaxImageSide) + "] pixels, got " +
                                   std::to_string(camera.height));
  }
  // Narrower than 0.01 degrees (a subnormal, found by fuzz_gaze) the focal length overflows.
  if (!std::isfinite(camera.fov_y_deg) || camera.fov_y_deg < 0.01 || camera.fov_y_deg >= 180.0) {
    throw InputError("fov_y_deg", "must be finite and in [0.01, 180) degrees");
  }
  const Pose& pose = camera.camera_to_world;
  if (!pose.position.allFinite() || pose.position.cwiseAbs().maxCoeff() > kMaxCameraCoordinate) {
    throw InputError("camera_pose", "position must be finite, each coordinate within 1e9 m");
  }
  if (!pose.orientation.coeffs().allFinite() ||
      std::abs(pose.orientation.norm() - 1.0) > kOrientationNormTol) {
    throw InputError("camera_pose", "orientation must be a finite unit quaternion");
  }
}

Pose opticalLookAt(const Vec3& eye, const Vec3& target, const Vec3& up) {
  if (!eye.allFinite() || !target.allFinite() || !up.allFinite()) {
    throw InputError("target", "eye, target and up must be finite");
  }
  const Vec3 forward_raw = target - eye;
  if (!(forward_raw.norm() > 0.0)) throw InputError("target", "must differ from the eye");
  const Vec3 z = forward_raw.normalized();
  Vec3 x = z.cross(up);  // optical x = right = forward x up
  if (x.norm() < 1e-9 * std::max(1.0, up.norm())) {
    x = z.cross(std::abs(z.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitY());
  }
  x.normalize();
  const Vec3 y = z.cross(x);  // optical y = down
  Mat3 r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  Pose pose;
  pose.position = eye;
  pose.orientation = Quat(r).normalized();
  return pose;
}

void Perception::setCamera(const Camera& camera) {
  validateCamera(camera);
  camera_ = camera;
  camera_.camera_to_world.orientation.normalize();
  world_to_camera_rotation_ = camera_.camera_to_world.orientation.conjugate().toRotationMatrix();
  camera_position_ = camera_.camera_to_world.position;
  focal_px_ = 0.5 * camera_.height / std::tan(0.5 * camera_.fov_y_deg * kPi / 180.0);
  // A fixation from the previous image stays where the viewer looks, kept on the new image.
  if (fixation_) {
    fixation_->x() = std::clamp(fixation_->x(), 0.0, static_cast<double>(camera_.width));
    fixation_->y() = std::clamp(fixation_->y(), 0.0, static_cast<double>(camera_.height));
  }
}

void Perception::setFixation(const Vec2& pixel) {
  if (!pixel.allFinite()) throw InputError("fixation", "must be finite");
  if (!onScreen(pixel)) {
    throw InputError("fixation", "must lie on the image [0, width] x [0, height]");
  }
  fixation_ = pixel;
}

bool Perception::onScreen(const Vec2& pixel) const {
  return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= camera_.width &&
         pixel.y() <= camera_.height;
}

std::optional<double> Perception::depthOf(const Vec3& world) const {
  const double z = world_to_camera_rotation_.row(2).dot(world - camera_position_);
  if (!(z > kNearDepth)) return std::nullopt;
  return z;
}

std::optional<Vec2> Perception::project(const Vec3& world) const {
  const Vec3 c = world_to_camera_rotation_ * (world - camera_position_);
  if (!(c.z() > kNearDepth)) return std::nullopt;
  const double inv_z = 1.0 / c.z();
  const Vec2 pixel(0.5 * camera_.width + focal_px_ * c.x() * inv_z, 0.5 * camera_.height + focal_px_ * c.y() * inv_z);
  if (!pixel.allFinite()) return std::nullopt;  // a point too far out to have a pixel (found by fuzz_gaze)
  return pixel;
}

Vec3 Perception::unproject(const Vec2& pixel, double depth) const {
  const Vec3 in_camera((pixel.x() - 0.5 * camera_.width) * depth / focal_px_,
                       (pixel.y() - 0.5 * camera_.height) * depth / focal_px_, depth);
  return camera_position_ + world_to_camera_rotation_.transpose() * in_camera;
}

Ray Perception::rayThrough(const Vec2& pixel) const {
  Ray ray;
  ray.origin = camera_position_;
  ray.direction = (unproject(pixel, 1.0) - camera_position_).normalized();
  return ray;
}

Perception::GazeWeight Perception::gazeWeight(const Vec3& world) const {
  GazeWeight out = pixelAndScale(world);
  if (out.px_per_metre > 0.0) out.weight = std::exp(-(out.pixel - *fixation_).norm() / 100.0);
  return out;
}

// Paper: the distance between the projections of the last intersecting
// centres. If either is behind the camera (a body straddling the camera
// plane), fall back to the 3D gap estimate seen at the given scale.
double Perception::projectedGap(const PairTest& test, double px_per_metre) const {
  const Vec3 a = world_to_camera_rotation_ * (test.lastCentreA() - camera_position_);
  const Vec3 b = world_to_camera_rotation_ * (test.lastCentreB() - camera_position_);
  if (!(a.z() > kNearDepth) || !(b.z() > kNearDepth)) return test.gapEstimate() * px_per_metre;
  const Vec2 d = focal_px_ * (a.head<2>() / a.z() - b.head<2>() / b.z());
  return d.norm();
}

PairPerception Perception::measure(const PairTest& test) const {
  PairPerception out;
  const Vec3 centre = test.centreOfCollision();
  const Vec3 c = world_to_camera_rotation_ * (centre - camera_position_);
  if (!(c.z() > kNearDepth) || !fixation_) {
    out.visible = false;
    out.eccentricity_px = std::numeric_limits<double>::infinity();
    return out;  // gaps and priority 0: nothing of it can be seen
  }
  const double px_per_metre = focal_px_ / c.z();
  out.px_per_metre = px_per_metre;
  const Vec2 pixel(0.5 * camera_.width + px_per_metre * c.x(),
                   0.5 * camera_.height + px_per_metre * c.y());
  out.visible = onScreen(pixel);
  out.eccentricity_px = (pixel - *fixation_).norm();

  out.gap_estimate_px = projectedGap(test, px_per_metre);
  out.gap_bound_px = test.gapBound() * px_per_metre;
  out.priority = perceivedInaccuracy(out.eccentricity_px, out.gap_estimate_px);
  return out;
}

}  // namespace stc
