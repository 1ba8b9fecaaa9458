// Start-up validation: each bad parameter is reported by name (ROS_FATAL
// "invalid ~<name>") and the process exits with status 1 instead of running
// on a guess. Parameters are set on the master under a fresh node name per
// case, then the node is started with that name.
#include "child_process.hpp"
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

namespace {

XmlRpc::XmlRpcValue list(std::initializer_list<double> values) {
  XmlRpc::XmlRpcValue v;
  v.setSize(static_cast<int>(values.size()));
  int i = 0;
  for (double x : values) v[i++] = x;
  return v;
}

XmlRpc::XmlRpcValue strings(std::initializer_list<const char*> values) {
  XmlRpc::XmlRpcValue v;
  v.setSize(static_cast<int>(values.size()));
  int i = 0;
  for (const char* x : values) v[i++] = std::string(x);
  return v;
}

struct Case {
  std::string program;  // collision_world_node, gaze_simulator, rockfall_spawner
  std::vector<std::pair<std::string, XmlRpc::XmlRpcValue>> params;
  std::string field;    // "" for a good set that must keep running
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The package's executables are built next to this test node.
std::string executable(const std::string& program) {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  std::string self(path, n > 0 ? static_cast<std::size_t>(n) : 0);
  return self.substr(0, self.rfind('/') + 1) + program;
}

struct Outcome {
  std::optional<int> status;  // nullopt: still running after the wait
  std::string output;
};

// Starts each case's program under a fresh name (bad_params_case_<first + i>)
// with its params, `at_once` at a time, and gives each one's exit status
// (nullopt while still running after `seconds`) and output. Side by side:
// one at a time, the 50 start-ups took 20 s.
std::vector<Outcome> runAll(const std::vector<Case>& cases, int first, double seconds, std::size_t at_once) {
  std::vector<Outcome> outcomes(cases.size());
  const auto nameOf = [&](std::size_t i) { return "bad_params_case_" + std::to_string(first + static_cast<int>(i)); };
  const auto logOf = [&](std::size_t i) {
    return "/tmp/stc_bad_params_" + std::to_string(getpid()) + "_" + std::to_string(first + static_cast<int>(i)) + ".log";
  };
  for (std::size_t begin = 0; begin < cases.size(); begin += at_once) {
    const std::size_t end = std::min(cases.size(), begin + at_once);
    std::vector<std::unique_ptr<stc_test::Child>> children;
    for (std::size_t i = begin; i < end; ++i) {
      for (const auto& [key, value] : cases[i].params) ros::param::set("/" + nameOf(i) + "/" + key, value);
      children.push_back(std::make_unique<stc_test::Child>(
          std::vector<std::string>{executable(cases[i].program), "__name:=" + nameOf(i)}, std::vector<std::string>{},
          logOf(i)));
      EXPECT_TRUE(children.back()->started())
          << "cannot start " << cases[i].program << ": " << std::strerror(children.back()->spawnError());
    }
    stc_test::spinUntil(
        [&] {
          return std::none_of(children.begin(), children.end(), [](const auto& c) { return c->running(); });
        },
        seconds);
    for (std::size_t i = begin; i < end; ++i) outcomes[i].status = children[i - begin]->exitStatus();
    children.clear();  // any still running is stopped before its log is read
    for (std::size_t i = begin; i < end; ++i) {
      outcomes[i].output = slurp(logOf(i));
      std::remove(logOf(i).c_str());
      ros::param::del("/" + nameOf(i));
    }
  }
  return outcomes;
}

TEST(BadParams, EachBadParameterIsNamedAndTheNodeExits) {
  const std::string bad_scene = "/tmp/stc_bad_scene_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(bad_scene) << "entities:\n  - {preset: cube, position: [0, 0]}\n";
  const std::string key_scene = "/tmp/stc_key_scene_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(key_scene) << "{[1]: 2}\n";  // a key that is not a name: once a crash at start-up
  const std::string heavy_scene = "/tmp/stc_heavy_scene_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(heavy_scene) << "gravity: [0, 0, -1e308]\n";
  const std::string world = "collision_world_node";
  const std::vector<Case> cases{
      {world, {{"rate", -1.0}}, "rate"},
      {world, {{"rate", "fast"}}, "rate"},
      {world, {{"scheduler", "fifo"}}, "scheduler"},
      {world, {{"solver", "gauss"}}, "solver"},
      {world, {{"unresolved_policy", "maybe"}}, "unresolved_policy"},
      {world, {{"sphere_test_budget", -5}}, "sphere_test_budget"},
      {world, {{"tick_budget", -16.7}}, "tick_budget"},
      {world, {{"tick_budget", "fast"}}, "tick_budget"},
      {world, {{"tick_budget", -2.0}}, "tick_budget"},  // -1 is none; other negatives are typos
      {world, {{"marker_levels", list({1, 9})}}, "marker_levels"},
      {world, {{"camera_position", list({1, 2, 3})}, {"camera_look_at", list({1, 2, 3})}}, "camera_look_at"},
      {world, {{"camera_fov_y", 200.0}}, "camera_fov_y"},
      {world, {{"gravity", list({0, 0})}}, "gravity"},
      {world, {{"queue_ratio", 0.5}}, "queue_ratio"},
      {world, {{"tree_levels", 12}}, "tree_levels"},
      {world, {{"max_entities", 0}}, "max_entities"},
      {world, {{"threads", -1}}, "threads"},
      {world, {{"reuse_tolerance", 1.5}}, "reuse_tolerance"},
      {world, {{"reuse_tolerance", -0.1}}, "reuse_tolerance"},
      {world, {{"scene", "/nonexistent/scene.yaml"}}, "scene"},
      {world, {{"scene", bad_scene}}, "scene entities[0].position"},
      {world, {{"scene", "rockfal"}}, "scene"},
      {world, {{"scene", key_scene}}, "scene"},
      {world, {{"scene", heavy_scene}}, "scene gravity"},
      {world, {{"gravity", list({0, 0, 1e308})}}, "gravity"},
      {world, {{"max_speed", -1.0}}, "max_speed"},
      {world, {{"strength_exponent", -0.5}}, "strength_exponent"},
      {world, {{"min_density", 10.0}, {"max_density", 1.0}}, "min_density"},
      {world, {{"default_density", 1e9}}, "default_density"},        // above ~max_density
      {world, {{"default_voxel_size", 5000.0}}, "default_voxel_size"},  // above ~max_voxel_size
      {world, {{"scene", "rockfall"}, {"scene_entities", 30000}}, "scene_entities"},
      {world, {{"entity_states_rate", 0.0}}, "entity_states_rate"},
      {world, {{"entity_states_rate", "often"}}, "entity_states_rate"},
      {world, {{"publish_clock", "yes"}}, "publish_clock"},
      {world, {{"error_report", "/nonexistent_dir/report.csv"}}, "error_report"},
      {world, {{"max_mesh_bytes", -1}}, "max_mesh_bytes"},
      {world, {{"max_mesh_vertices", "many"}}, "max_mesh_vertices"},
      {world, {{"max_mesh_triangles", 0}}, "max_mesh_triangles"},
      {world, {{"mesh_roots", strings({"/tmp", "meshes"})}}, "mesh_roots[1]"},  // not absolute
      {world, {{"mesh_roots", strings({"/nonexistent_dir"})}}, "mesh_roots[0]"},
      {world, {{"mesh_roots", "/tmp"}}, "mesh_roots"},  // a list of folders, not one
      {world, {{"save_dir", "saves"}}, "save_dir"},  // not absolute
      {world, {{"autosave_period", -0.5}}, "autosave_period"},
      {"gaze_simulator", {{"mode", "blink"}}, "mode"},
      {"gaze_simulator", {{"mode", "follow"}}, "target"},
      {"rockfall_spawner", {{"rate", 0.0}}, "rate"},
      {"rockfall_spawner", {{"region_min", list({0, 0, 5})}, {"region_max", list({1, 1, 4})}}, "region_max"},
  };
  const std::vector<Outcome> outcomes = runAll(cases, 0, 20.0, 8);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    SCOPED_TRACE(c.program + " ~" + c.field);
    const auto& [status, output] = outcomes[i];
    EXPECT_TRUE(status.has_value()) << "still running with a bad ~" << c.field;
    EXPECT_EQ(status.value_or(-1), 1);
    EXPECT_NE(output.find("invalid ~" + c.field + ":"), std::string::npos) << "output:\n" << output;
  }
  std::remove(bad_scene.c_str());
  std::remove(key_scene.c_str());
  std::remove(heavy_scene.c_str());
}

TEST(BadParams, AGoodSetKeepsRunning) {
  const Case good{"collision_world_node",
                  {{"rate", 30}, {"scheduler", "round_robin"}, {"marker_levels", list({0, 3})}, {"tick_budget", 16.7},
                   {"camera_position", list({0, -3, 1})}, {"camera_look_at", list({0, 0, 0.5})},
                   {"reuse_tolerance", 0.05}, {"default_density", 2500.0}, {"default_voxel_size", 0.1},
                   {"mesh_roots", strings({"/tmp"})}, {"max_mesh_triangles", 500000}, {"solver", "soft"}},
                  ""};
  const auto [status, output] = runAll({good}, 1000, 3.0, 1).front();
  EXPECT_FALSE(status.has_value()) << "exited with " << status.value_or(-1) << ":\n" << output;
  EXPECT_EQ(output.find("FATAL"), std::string::npos) << output;
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "bad_params_test"); }
