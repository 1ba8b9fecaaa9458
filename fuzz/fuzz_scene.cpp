// Fuzz target: the YAML scene parser (src/ros/scene_file.cpp, ROS-free) on
// arbitrary text, then the parsed scene added to a World. Only stc::InputError
// may come out: a scene file is never a reason for anything else.
#include "fuzz_support.hpp"
#include "sphere_tree_collision/scene/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static stc::World world(stc_fuzz::smallWorldConfig());
  world.clear();
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const stc::Scene scene = stc::parseSceneYaml(text);
    stc::validateGravity(scene.gravity, world.config().limits);  // as the node's World(config) does
    const std::vector<stc::EntityId> ids = stc::addScene(world, scene);
    stc_fuzz::require(ids.size() == scene.entities.size() && world.entityCount() == ids.size(),
                      "addScene returned a different count");
  } catch (const stc::InputError&) {
    return 0;
  }
  const stc::TickReport report = world.step(1.0 / 60.0, stc::Budget::ofSphereTests(20000));
  stc_fuzz::checkWorldAfterStep(world, report);
  return 0;
}
