// GazeModel: where the viewer looks at time t (fixed, saccades, follow).
#include "sphere_tree_collision/gaze_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace stc {
namespace {

const std::array<std::pair<GazeMode, const char*>, 3> kGazeModes{{
    {GazeMode::Fixed, "fixed"}, {GazeMode::Saccades, "saccades"}, {GazeMode::Follow, "follow"}}};

// SplitMix64 finaliser: a well-mixed 64-bit hash, so saccade k is a pure function of (seed, k).
std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
double unitFrom(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

Vec2 clampOnto(const Vec2& p, const Camera& c) {
  return Vec2(std::clamp(p.x(), 0.0, static_cast<double>(c.width)),
              std::clamp(p.y(), 0.0, static_cast<double>(c.height)));
}

}  // namespace

GazeMode parseGazeMode(const std::string& name) {
  std::string allowed;
  for (const auto& [mode, text] : kGazeModes) {
    if (name == text) return mode;
    allowed += (allowed.empty() ? "" : ", ") + std::string(text);
  }
  throw InputError("gaze_mode", "unknown value '" + name + "' (expected one of: " + allowed + ")");
}

const char* toString(GazeMode mode) {
  for (const auto& [m, text] : kGazeModes) {
    if (m == mode) return text;
  }
  return "?";
}

GazeModel::GazeModel(const GazeParams& params) : params_(params) {
  if (!std::isfinite(params.saccade_period_s) || params.saccade_period_s <= 0.0) {
    throw InputError("saccade_period_s", "must be finite and > 0");
  }
  if (!std::isfinite(params.saccade_margin) || params.saccade_margin < 0.0 ||
      params.saccade_margin >= 0.5) {
    throw InputError("saccade_margin", "must be in [0, 0.5)");
  }
  if (params.pixel && !params.pixel->allFinite()) throw InputError("pixel", "must be finite");
}

Vec2 GazeModel::fixationAt(double t, const World& world) {
  const Camera& camera = world.perception().camera();
  const Vec2 centre(0.5 * camera.width, 0.5 * camera.height);
  switch (params_.mode) {
    case GazeMode::Fixed:
      return clampOnto(params_.pixel.value_or(centre), camera);
    case GazeMode::Saccades: {
      const double k = std::floor(std::max(0.0, t) / params_.saccade_period_s);
      const std::uint64_t h = mix((static_cast<std::uint64_t>(params_.seed) << 32) ^
                                  static_cast<std::uint64_t>(k));
      const double m = params_.saccade_margin;
      const double u = m + (1.0 - 2.0 * m) * unitFrom(h);
      const double v = m + (1.0 - 2.0 * m) * unitFrom(mix(h));
      return Vec2(u * camera.width, v * camera.height);
    }
    case GazeMode::Follow: {
      if (const auto index = world.indexOf(params_.target)) {
        if (const auto pixel = world.perception().project(world.bodies()[*index].pose.position)) {
          last_follow_ = clampOnto(*pixel, camera);
        }
      }
      return last_follow_ ? clampOnto(*last_follow_, camera) : centre;
    }
  }
  return centre;
}

}  // namespace stc
