// Rest test by motion (rest_test.hpp): three balls per body, grown point by point.
#include "rest_test.hpp"

namespace stc {
namespace {

// Grows `ball` the least that keeps it holding what it held and also holds p
// (the new ball touches p and the far side of the old one).
void grow(Sphere& ball, const Vec3& p) {
  const Vec3 d = p - ball.centre;
  const double distance = d.norm();
  if (distance <= ball.radius) return;
  const double radius = 0.5 * (ball.radius + distance);
  ball.centre += ((radius - ball.radius) / distance) * d;
  ball.radius = radius;
}

}  // namespace

void RestTest::add(double reach) {
  reach_.push_back(reach);
  balls_.emplace_back();
  age_.push_back(0.0);
  restart(balls_.size() - 1);
}

void RestTest::remove(std::size_t index, std::size_t last) {
  reach_[index] = reach_[last];
  balls_[index] = balls_[last];
  age_[index] = age_[last];
  reach_.pop_back();
  balls_.pop_back();
  age_.pop_back();
}

void RestTest::clear() {
  reach_.clear();
  balls_.clear();
  age_.clear();
}

std::array<Vec3, 3> RestTest::pointsOf(std::size_t body, const Pose& pose) const {
  const Mat3 r = pose.orientation.toRotationMatrix();
  const double reach = reach_[body];
  return {pose.position, pose.position + reach * r.col(0), pose.position + reach * r.col(1)};
}

bool RestTest::update(std::size_t body, const Pose& pose, double dt, double window, double max_radius) {
  std::array<Sphere, 3>& balls = balls_[body];
  const std::array<Vec3, 3> points = pointsOf(body, pose);
  const bool fresh = balls[0].radius < 0.0;
  bool fits = fresh;  // a fresh start holds one pose: nothing has moved yet
  if (!fresh) {
    fits = true;
    for (int k = 0; k < 3 && fits; ++k) {
      grow(balls[k], points[k]);
      fits = balls[k].radius <= max_radius;
    }
    age_[body] += dt;
    if (fits && age_[body] < window) return true;
  }
  for (int k = 0; k < 3; ++k) balls[k] = Sphere{points[k], 0.0};
  age_[body] = 0.0;
  return fits;
}

}  // namespace stc
