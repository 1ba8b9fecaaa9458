// What the viewer looks at: a ray from the perception camera cast into the
// world. The bodies are their bounding balls here (centre of mass, radius
// ShapeInfo::bounding_radius): enough to place a gaze marker, never a contact.
#pragma once

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/world.hpp"

#include <cstddef>
#include <optional>

namespace stc {

struct RayHit {
  double distance = 0.0;  // along the ray, metres
  std::size_t body = 0;   // dense index into World::bodies()
};

// The nearest body whose bounding ball the ray meets at distance >= 0 (from
// inside a ball: where the ray leaves it). nullopt when it meets none.
std::optional<RayHit> castRay(const World& world, const Ray& ray);

// Where the gaze ray through the fixation first meets the scene: a body's
// bounding ball, else the ground plane z = 0 when the ray points down to it
// from above, else kGazeFallbackDistance out. nullopt without a fixation.
constexpr double kGazeFallbackDistance = 5.0;  // metres
std::optional<Vec3> gazeTarget(const World& world);

}  // namespace stc
