// Where a simulated viewer looks at time t: a fixed pixel, seeded saccades,
// or the projection of one entity (scenes, benches and the gaze simulator
// node use it to drive Perception::setFixation). Core only.
#pragma once

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/world.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace stc {

enum class GazeMode : std::uint8_t {
  Fixed,     // one pixel
  Saccades,  // jumps to a new seeded random pixel every period (the eye's saccades)
  Follow,    // the projection of one entity's centre
};
// "fixed" | "saccades" | "follow"; throws InputError("gaze_mode").
GazeMode parseGazeMode(const std::string& name);
const char* toString(GazeMode mode);

struct GazeParams {
  GazeMode mode = GazeMode::Fixed;
  std::optional<Vec2> pixel;           // fixed: the pixel (default: image centre)
  double saccade_period_s = 0.3;       // saccades: time between jumps, > 0
  double saccade_margin = 0.1;         // saccades: keep this fraction of the image off each edge
  std::uint32_t seed = 1;              // saccades: the sequence of targets
  EntityId target = kInvalidEntity;    // follow: the entity
};

// The fixation at time t on the image of world.perception().camera(), always
// on the image (ready for Perception::setFixation). Pure in t for fixed and
// saccades (the k-th saccade target is a hash of (seed, k), so replaying a time
// gives the same pixel). Follow: the target's projection clamped onto the
// image; while the target is behind the camera or gone, the last pixel it gave
// (the image centre before any).
class GazeModel {
 public:
  // Throws InputError("saccade_period_s"), ("saccade_margin") or ("pixel").
  explicit GazeModel(const GazeParams& params);
  Vec2 fixationAt(double t, const World& world);
  const GazeParams& params() const { return params_; }

 private:
  GazeParams params_;
  std::optional<Vec2> last_follow_;
};

}  // namespace stc
