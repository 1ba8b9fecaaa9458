#include "sphere_tree_collision/ros/entity_display.hpp"

#include <cmath>

namespace stc_ros {

std::string entityFrame(stc::EntityId id, const std::string& name) {
  return name.empty() ? "entity_" + std::to_string(id) : name;
}

Rgba paletteColor(stc::EntityId id) {
  // HSV with golden-ratio hue steps, saturation 0.6, value 0.9.
  const double h = std::fmod(0.12 + 0.618033988749895 * id, 1.0) * 6.0;
  const double s = 0.6, v = 0.9;
  const int sector = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (sector) {
    case 0: r = v; g = t; b = p; break;
    case 1: r = q; g = v; b = p; break;
    case 2: r = p; g = v; b = t; break;
    case 3: r = p; g = q; b = v; break;
    case 4: r = t; g = p; b = v; break;
    default: r = v; g = p; b = q; break;
  }
  return {static_cast<float>(r), static_cast<float>(g), static_cast<float>(b), 1.0f};
}

}  // namespace stc_ros
