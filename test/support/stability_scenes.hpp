// The stiff and extreme scenes of issue 4 (item 5), built on a World, and one
// runner that measures what the stability test asserts and the stability
// bench tabulates: finiteness, energy gain, penetration, speed, drift.
#pragma once

#include "sphere_tree_collision/world.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace stc::stability {

struct Scene {
  std::string name;
  std::unique_ptr<World> world;
  double dt = 1.0 / 60.0;
  int steps = 600;
  Budget budget = Budget::unlimited();
  double voxel = 0.05;        // voxel size of the moving bodies: the unit of penetration and drift
  int settle_steps = 120;     // drift is measured from here to the end
  std::vector<std::size_t> movers;  // dense indices of the movable bodies
  // No body can be faster without energy gain: the fastest initial speed plus
  // free fall across the scene (sqrt(2 |g| extent)), with a 10% margin.
  double speed_bound = 0.0;
};

// A floor (static 8 x 8 x 1 plate of 5-voxel cells, top at z = 0) and `count`
// cubes of 8 voxels stacked on it, gravity -z. The stack rests from the start.
Scene stack(int count = 10, double voxel = 0.05, double dt = 1.0 / 60.0, double seconds = 10.0,
            double settle_seconds = 2.0, const ResponseOptions& response = ResponseOptions{});
// A heavy cube (8 voxels) on a 2 x 2 of light cubes (4 voxels), mass ratio
// `ratio` (heavy : one light), on the floor. The light cubes stand `gap`
// metres apart (0: face to face, bracing each other).
Scene massRatio(double ratio = 1000.0, double seconds = 5.0,
                const ResponseOptions& response = ResponseOptions{}, double gap = 0.0);
// A one-voxel sphere at `speed` m/s straight at a one-voxel-thick static
// plate (16 x 16 x 1), no gravity; the sphere starts 1 m above the plate.
Scene fastSphere(double speed = 100.0, double seconds = 0.5,
                 const ResponseOptions& response = ResponseOptions{});
// A thin rod (16 x 3 x 1 voxels: three distinct principal moments) spinning
// at `spin` rad/s about its intermediate axis, slightly perturbed, no gravity.
Scene spinningRod(double spin = 100.0, double seconds = 10.0,
                  const ResponseOptions& response = ResponseOptions{});
// `count` touching balls (8 voxels across) in a row along x, restitution 1,
// friction 0, no gravity; the first one at 1 m/s towards the others.
Scene newtonsCradle(int count = 5, double seconds = 2.0,
                    const ResponseOptions& response = ResponseOptions{});
// The paper's worst case: `count` rocks dropped into one corner of the closed
// box (scenes.hpp CornerDrift: gravity towards the box's corner).
Scene cornerPile(int count = 500, int resolution = 4, double seconds = 4.0,
                 const Budget& budget = Budget::unlimited(),
                 const ResponseOptions& response = ResponseOptions{});

struct Metrics {
  std::size_t nan_count = 0;         // body-ticks with a non-finite pose, velocity or inertia
  double energy_gain = 0.0;          // max over ticks of (E(t) - E(0)) / E_ref (E_ref: KE(0) + potential above the lowest body)
  double max_penetration = 0.0;      // max over ticks of the deepest contact, in voxels
  double max_speed = 0.0;            // m/s, over ticks and bodies
  double final_max_speed = 0.0;      // m/s, over bodies at the end
  double drift = 0.0;                // voxels per second: max over movers of |x(end) - x(settle)| / time
  double steps_per_second = 0.0;     // wall clock (a figure, never asserted)
  int steps = 0;
};

// Runs the scene; `observe` (optional) sees the world after every step.
Metrics run(Scene& scene, const std::function<void(const World&, int step)>& observe = {});

}  // namespace stc::stability
