// The `--scenes name:bodies[,name:bodies...]` list of the benchmarks that run
// built-in scenes at given sizes, and the flags of those that time them.
#pragma once

#include "bench_args.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/types.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace stc_bench {

struct SceneCase {
  stc::SceneKind kind = stc::SceneKind::CornerDrift;
  int bodies = 500;
};

// "rockfall:1000", or a bare "rockfall": that scene's cases in `defaults`
// (500 bodies when it has none). Empty items are skipped. Throws
// InputError("--scenes") on a count below 1 or an unknown name.
inline std::vector<SceneCase> parseSceneCases(const std::string& list, const std::vector<SceneCase>& defaults = {}) {
  std::vector<SceneCase> cases;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string item = list.substr(start, comma - start);
    start = comma + 1;
    if (item.empty()) continue;
    const std::size_t colon = item.find(':');
    SceneCase c;
    c.kind = stc::parseScene(item.substr(0, colon));
    if (colon == std::string::npos) {
      const std::size_t before = cases.size();
      for (const SceneCase& d : defaults) {
        if (d.kind == c.kind) cases.push_back(d);
      }
      if (cases.size() == before) cases.push_back(c);
      continue;
    }
    c.bodies = std::stoi(item.substr(colon + 1));
    if (c.bodies < 1) throw stc::InputError("--scenes", "entity count must be >= 1 in '" + item + "'");
    cases.push_back(c);
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
  // or --settle, or --smoke (every scene small, 3 ticks, no settling: that the
  // bench runs, scripts/bench_smoke.sh); false: not one of them. Throws
  // InputError naming it.
  bool take(const std::string& flag, Args& args) {
    if (flag == "--smoke") {
      for (SceneCase& c : cases) c.bodies = std::min(c.bodies, 100);
      seconds = cube_seconds = 0.05;
      settle = 0.0;
    } else if (flag == "--scenes") {
      cases = parseSceneCases(args.required(), cases);
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
