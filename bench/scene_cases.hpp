// The `--scenes name:bodies[,name:bodies...]` list of the benchmarks that run
// built-in scenes at given sizes, and the flags of those that time them.
#pragma once

#include "bench_args.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/types.hpp"

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

// What a bench that times built-in scenes runs: the scenes, the simulated
// seconds timed (cube_box, much slower a tick, has its own) and the seconds
// run first, untimed.
struct SceneTiming {
  std::vector<SceneCase> cases{{stc::SceneKind::CornerDrift, 500},
                               {stc::SceneKind::Rockfall, 1000},
                               {stc::SceneKind::PackedBox, 500},
                               {stc::SceneKind::CubeBox, 10000}};
  double seconds = 3.0;
  double cube_seconds = 1.5;
  double settle = 1.0;

  // Takes `flag` and its value when it is --scenes, --seconds, --cube-seconds
  // or --settle (false: not one of them); throws InputError naming it.
  bool take(const std::string& flag, Args& args) {
    if (flag == "--scenes") {
      cases = parseSceneCases(args.required());
    } else if (flag == "--seconds") {
      seconds = std::stod(args.required());
    } else if (flag == "--cube-seconds") {
      cube_seconds = std::stod(args.required());
    } else if (flag == "--settle") {
      settle = std::stod(args.required());
    } else {
      return false;
    }
    if (!(seconds > 0.0) || !(cube_seconds > 0.0) || !(settle >= 0.0)) {
      throw stc::InputError(flag, "seconds must be > 0 and --settle >= 0");
    }
    return true;
  }
  double secondsOf(const SceneCase& c) const { return c.kind == stc::SceneKind::CubeBox ? cube_seconds : seconds; }
};

}  // namespace stc_bench
