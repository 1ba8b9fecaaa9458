// Fuzz target: the gaze path. A camera (pose, image size, field of view), a
// fixation pixel and clicked points to project, then a tick whose scheduler
// and perceptual measures use the fixation. Only stc::InputError may come out;
// everything the tick reports must be finite.
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  // Shapes are built once; every input starts from the same four overlapping
  // bodies (pairs to measure) and the same camera.
  static stc::World world(stc_fuzz::smallWorldConfig());
  static const char* const kPresets[] = {"cube", "rod", "sphere", "ring"};
  world.clear();
  for (int i = 0; i < 4; ++i) {
    stc::EntitySpec spec;
    spec.shape = world.addShape(kPresets[i], stc::makePreset(kPresets[i], stc::PresetParams{8, 0.05, 1}));
    spec.pose.position = stc::Vec3(0.15 * i, 0.05 * (i % 2), 0.0);
    world.addEntity(spec);
  }
  stc::Camera start;
  start.camera_to_world = stc::opticalLookAt(stc::Vec3(0, -2, 1), stc::Vec3(0.2, 0, 0));
  world.perception().setCamera(start);
  world.perception().clearFixation();
  stc::Perception& perception = world.perception();

  for (int step = 0; step < 8 && in.remaining_bytes() > 0; ++step) {
    try {
      switch (in.ConsumeIntegralInRange<int>(0, 3)) {
        case 0: {
          stc::Camera camera;
          camera.width = in.ConsumeBool() ? in.ConsumeIntegralInRange<int>(1, 4000) : in.ConsumeIntegral<int>();
          camera.height = in.ConsumeBool() ? in.ConsumeIntegralInRange<int>(1, 4000) : in.ConsumeIntegral<int>();
          camera.fov_y_deg = stc_fuzz::pickDouble(in, 1, 179);
          if (in.ConsumeBool()) {
            camera.camera_to_world = stc::opticalLookAt(stc_fuzz::pickVec3(in, -5, 5), stc_fuzz::pickVec3(in, -1, 1));
          } else {
            camera.camera_to_world.position = stc_fuzz::pickVec3(in, -5, 5);
            camera.camera_to_world.orientation = stc_fuzz::pickOrientation(in);
          }
          perception.setCamera(camera);
          break;
        }
        case 1: {
          const double x = stc_fuzz::pickDouble(in, 0, perception.camera().width);
          perception.setFixation(stc::Vec2(x, stc_fuzz::pickDouble(in, 0, perception.camera().height)));
          break;
        }
        case 2: {  // a clicked point: projected, then fixated when on the image
          const auto pixel = perception.project(stc_fuzz::pickVec3(in, -3, 3));
          if (pixel) {
            stc_fuzz::require(pixel->allFinite(), "projection of a finite point is not finite");
            perception.setFixation(*pixel);
          }
          break;
        }
        default: perception.clearFixation(); break;
      }
    } catch (const stc::InputError&) {
    }
    if (perception.hasFixation()) {
      stc_fuzz::require(perception.fixation()->allFinite() && perception.onScreen(*perception.fixation()),
                        "accepted fixation not finite or off screen");
    }
  }
  const stc::TickReport report = world.step(0.0, stc::Budget::ofSphereTests(in.ConsumeIntegralInRange<int>(0, 5000)));
  stc_fuzz::checkWorldAfterStep(world, report);
  stc_fuzz::require(std::isfinite(report.accuracy.perceived_inaccuracy) && std::isfinite(report.accuracy.geometric_inaccuracy),
                    "non-finite inaccuracy");
  for (const stc::Contact& c : world.contacts()) stc_fuzz::require(std::isfinite(c.priority), "non-finite priority");
  return 0;
}
