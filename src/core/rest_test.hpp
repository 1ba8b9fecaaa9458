// Is a body at rest? Judged by where it went, not by its velocity of the
// moment (as Jolt does): three points fixed in the body, its centre of mass
// and two points at its reach along its own x and y axes, are each kept in
// a ball that grows to hold every position the point took in the current
// window of time. The body rests while every ball stays within a radius; a
// ball that grows past it restarts the test at the body's pose. A window that
// ends with every ball inside starts the next one at the pose then, still
// resting: a body creeping slower than radius / window stays at rest however
// long it creeps, as a body slower than a speed threshold would.
//
// Why not the velocity: in a deep pile the solver leaves rocks rocking in
// place (stored spin above a fixed threshold, angle turned back and forth:
// docs/sleeping.md), so one of thousands of rocks is always "moving" by its
// velocity although none goes anywhere. Why points at the reach: a turn of
// angle a moves the body's surface by reach * a, so the same radius asks a
// big body to turn more slowly than a small one (a size-scaled angular
// threshold, as Box2D v3's |v| + extent * |w|).
#pragma once

#include "enclosing_sphere.hpp"
#include "sphere_tree_collision/types.hpp"

#include <array>
#include <vector>

namespace stc {

class RestTest {
 public:
  // Flat arrays indexed like the World's bodies: `reach` is the body's
  // largest distance from its centre of mass (ShapeInfo::bounding_radius).
  void add(double reach);
  void remove(std::size_t index, std::size_t last);  // index takes last's place
  void clear();

  // The next update starts the test afresh at the body's pose then.
  void restart(std::size_t body) { balls_[body][0].radius = -1.0; }
  // Adds the pose, dt seconds after the last, to the body's balls. True when
  // each still fits in `max_radius`; false when one grew past it (the test
  // restarts at `pose`). Windows last `window` seconds.
  bool update(std::size_t body, const Pose& pose, double dt, double window, double max_radius);
  // A body's balls and the age of its window (a saved world's: CarriedState).
  const std::array<Sphere, 3>& balls(std::size_t body) const { return balls_[body]; }
  double age(std::size_t body) const { return age_[body]; }
  void restore(std::size_t body, const std::array<Sphere, 3>& balls, double age) {
    balls_[body] = balls;
    age_[body] = age;
  }

 private:
  std::array<Vec3, 3> pointsOf(std::size_t body, const Pose& pose) const;
  std::vector<double> reach_;
  std::vector<std::array<Sphere, 3>> balls_;  // radius < 0 in [0]: empty
  std::vector<double> age_;                   // seconds since the window began
};

}  // namespace stc
