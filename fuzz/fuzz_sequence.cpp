// Fuzz target: a series of spawns, despawns, gazes and ticks applied to one
// World. After every tick: every body finite and within the limits, the entity
// count equal to what was added minus what was removed (despawned or
// quarantined), and the broad phase's pairs equal to a brute-force check.
#include "fuzz_support.hpp"
#include "sphere_tree_collision/scene/entity_request.hpp"

#include <vector>

namespace {

stc::EntityRequest pickEntity(FuzzedDataProvider& in) {
  static const char* const kPresets[] = {"cube", "sphere", "rock", "rod", "plate", "L", "ring"};
  stc::EntityRequest r;
  r.preset = kPresets[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kPresets) - 1)];
  r.preset_params.resolution = in.ConsumeIntegralInRange<int>(1, 10);
  r.preset_params.voxel_size = in.ConsumeBool() ? 0.05 : stc_fuzz::pickDouble(in, 0.01, 0.3);
  r.preset_params.seed = in.ConsumeIntegralInRange<std::uint32_t>(0, 3);
  r.spec.pose.position = stc_fuzz::pickVec3(in, -1.5, 1.5);
  r.spec.pose.orientation = stc_fuzz::pickOrientation(in);
  r.spec.linear_velocity = stc_fuzz::pickVec3(in, -30, 30);
  r.spec.angular_velocity = stc_fuzz::pickVec3(in, -30, 30);
  r.spec.density = stc_fuzz::pickDouble(in, 1, 20000);
  r.spec.material.restitution = stc_fuzz::pickDouble(in, 0, 1);
  r.spec.material.friction = stc_fuzz::pickDouble(in, 0, 2);
  r.spec.is_static = in.ConsumeIntegralInRange<int>(0, 5) == 0;
  if (in.ConsumeBool()) r.spec.box_mode = in.ConsumeBool() ? stc::BoxMode::Dynamic : stc::BoxMode::FixedCube;
  return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  stc::WorldConfig config = stc_fuzz::smallWorldConfig();
  if (in.ConsumeBool()) config.gravity = stc::Vec3(0, 0, -9.81);
  config.limits.world_extent = in.ConsumeBool() ? 1e4 : 5.0;  // small: bodies leave the world often
  config.limits.max_speed = in.ConsumeBool() ? 1e3 : 40.0;    // small: collisions push bodies past it
  config.scheduler.kind = static_cast<stc::SchedulerKind>(in.ConsumeIntegralInRange<int>(0, 3));
  stc::World world(config);
  std::size_t expected = 0;

  for (int op = 0; op < 80 && in.remaining_bytes() > 0; ++op) {
    switch (in.ConsumeIntegralInRange<int>(0, 4)) {
      case 0:
      case 1:
        try {
          stc::addRequest(world, pickEntity(in));
          ++expected;
        } catch (const stc::InputError&) {
        }
        break;
      case 2:
        if (world.entityCount() > 0) {
          const std::size_t index = in.ConsumeIntegralInRange<std::size_t>(0, world.entityCount() - 1);
          stc_fuzz::require(world.removeEntity(world.entityIds()[index]), "removing a live entity failed");
          --expected;
        }
        break;
      case 3:
        try {
          if (in.ConsumeBool()) {
            world.perception().setFixation(stc::Vec2(stc_fuzz::pickDouble(in, 0, 1280), stc_fuzz::pickDouble(in, 0, 720)));
          } else {
            world.perception().clearFixation();
          }
        } catch (const stc::InputError&) {
        }
        break;
      default: {
        static const double kDts[] = {1.0 / 60.0, 1.0 / 30.0, 0.1, 0.0, 1e-6};
        const double dt = kDts[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kDts) - 1)];
        const stc::Budget budget = in.ConsumeBool() ? stc::Budget::unlimited()
                                                    : stc::Budget::ofSphereTests(in.ConsumeIntegralInRange<int>(0, 3000));
        const stc::TickReport report = world.step(dt, budget);
        expected -= world.quarantined().size();
        stc_fuzz::require(report.bodies.quarantined + report.bodies.left_world == world.quarantined().size(),
                          "quarantine counts differ from the list");
        stc_fuzz::require(world.entityCount() == expected, "entity count differs from spawns - removals");
        stc_fuzz::checkWorldAfterStep(world, report);
        break;
      }
    }
  }
  return 0;
}
