#include "sphere_tree_collision/perception_ray.hpp"

#include <cmath>

namespace stc {

std::optional<RayHit> castRay(const World& world, const Ray& ray) {
  std::optional<RayHit> nearest;
  const auto& bodies = world.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const double r = world.shape(world.bodyShapes()[i]).bounding_radius;
    const Vec3 to_centre = bodies[i].pose.position - ray.origin;
    const double t_mid = to_centre.dot(ray.direction);  // closest approach to the centre
    const double miss2 = to_centre.squaredNorm() - t_mid * t_mid;
    if (!(miss2 <= r * r)) continue;
    const double half_chord = std::sqrt(r * r - miss2);
    const double t = t_mid - half_chord >= 0.0 ? t_mid - half_chord : t_mid + half_chord;
    // A body whose state or ball is not finite is never what the viewer looks at.
    if (!(t >= 0.0) || !std::isfinite(t) || (nearest && t >= nearest->distance)) continue;
    nearest = RayHit{t, i};
  }
  return nearest;
}

std::optional<Vec3> gazeTarget(const World& world) {
  const Perception& perception = world.perception();
  if (!perception.hasFixation()) return std::nullopt;
  const Ray ray = perception.rayThrough(*perception.fixation());
  if (const auto hit = castRay(world, ray)) return ray.origin + hit->distance * ray.direction;
  if (ray.direction.z() < -1e-6 && ray.origin.z() > 0.0) {
    return ray.origin + (-ray.origin.z() / ray.direction.z()) * ray.direction;
  }
  return ray.origin + kGazeFallbackDistance * ray.direction;
}

}  // namespace stc
