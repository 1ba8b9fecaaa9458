// The `--scenes name:bodies[,name:bodies...]` list of the benchmarks that run
// built-in scenes at given sizes.
#pragma once

#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include <string>
#include <vector>

namespace stc_bench {

struct SceneCase {
  stc::SceneKind kind = stc::SceneKind::CornerDrift;
  int bodies = 500;
};

// "corner_drift:500" (the count may be left out: 500); throws InputError("--scenes").
inline SceneCase parseSceneCase(const std::string& item) {
  const std::size_t colon = item.find(':');
  SceneCase c;
  c.kind = stc::parseScene(item.substr(0, colon));
  if (colon != std::string::npos) c.bodies = std::stoi(item.substr(colon + 1));
  if (c.bodies < 1) throw stc::InputError("--scenes", "entity count must be >= 1");
  return c;
}

inline std::vector<SceneCase> parseSceneCases(const std::string& list) {
  std::vector<SceneCase> cases;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = list.find(',', start);
    cases.push_back(parseSceneCase(list.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return cases;
}

inline std::string caseName(const SceneCase& c) { return std::string(stc::toString(c.kind)) + "_" + std::to_string(c.bodies); }

}  // namespace stc_bench
