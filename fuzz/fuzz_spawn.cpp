// Fuzz target: one SpawnEntity message, as the node receives it, through
// toEntityRequest and addRequest into a World, then a few ticks. Only
// stc::InputError may come out; the world must stay within its limits.
#include "fuzz_support.hpp"
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/mesh_resource.hpp"

namespace {

std::string pickPreset(FuzzedDataProvider& in) {
  static const char* const kNames[] = {"cube", "sphere", "rock", "rod", "plate", "L", "ring", "", "cubes", "RING"};
  if (in.ConsumeBool()) return kNames[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kNames) - 1)];
  return in.ConsumeRandomLengthString(12);
}

void fillPoint(FuzzedDataProvider& in, double lo, double hi, double& x, double& y, double& z) {
  x = stc_fuzz::pickDouble(in, lo, hi);
  y = stc_fuzz::pickDouble(in, lo, hi);
  z = stc_fuzz::pickDouble(in, lo, hi);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  static stc::World world(stc_fuzz::smallWorldConfig());  // shapes stay cached across inputs, as in the node
  world.clear();

  for (int spawn = 0; spawn < 3 && in.remaining_bytes() > 0; ++spawn) {
    sphere_tree_collision::SpawnEntity msg;
    msg.name = in.ConsumeBool() ? std::string() : in.ConsumeRandomLengthString(70);
    if (in.ConsumeBool()) {  // explicit grid
      for (auto& d : msg.dims) d = in.ConsumeBool() ? in.ConsumeIntegralInRange<std::uint32_t>(0, 6) : in.ConsumeIntegral<std::uint32_t>();
      const std::size_t cells = std::min<std::size_t>(512, std::size_t(msg.dims[0] % 9) * (msg.dims[1] % 9) * (msg.dims[2] % 9));
      msg.occupancy = in.ConsumeBytes<std::uint8_t>(in.ConsumeBool() ? cells : in.ConsumeIntegralInRange<std::size_t>(0, 600));
    } else {
      msg.preset = pickPreset(in);
      msg.resolution = in.ConsumeBool() ? in.ConsumeIntegralInRange<std::uint32_t>(0, 12) : in.ConsumeIntegral<std::uint32_t>();
      msg.seed = in.ConsumeIntegral<std::uint32_t>();
    }
    msg.voxel_size = stc_fuzz::pickDouble(in, 0.005, 0.2);
    fillPoint(in, -5, 5, msg.pose.position.x, msg.pose.position.y, msg.pose.position.z);
    const stc::Quat q = stc_fuzz::pickOrientation(in);
    msg.pose.orientation.w = q.w();
    msg.pose.orientation.x = q.x();
    msg.pose.orientation.y = q.y();
    msg.pose.orientation.z = q.z();
    fillPoint(in, -20, 20, msg.twist.linear.x, msg.twist.linear.y, msg.twist.linear.z);
    fillPoint(in, -20, 20, msg.twist.angular.x, msg.twist.angular.y, msg.twist.angular.z);
    msg.density = stc_fuzz::pickDouble(in, 1, 20000);
    msg.restitution = stc_fuzz::pickDouble(in, 0, 1);
    msg.friction = stc_fuzz::pickDouble(in, 0, 2);
    msg.color.r = static_cast<float>(stc_fuzz::pickDouble(in, 0, 1));
    msg.color.a = static_cast<float>(stc_fuzz::pickDouble(in, 0, 1));
    msg.is_static = in.ConsumeIntegralInRange<int>(0, 4) == 0;
    static const char* const kFaces[] = {"+x", "-x", "+y", "-y", "+z", "-z", "", "z", "-Z", "+x "};
    for (int f = in.ConsumeIntegralInRange<int>(0, 3); f > 0; --f) {
      msg.closed_faces.push_back(kFaces[in.ConsumeIntegralInRange<int>(0, 9)]);
    }

    const std::size_t before = world.entityCount();
    try {
      stc::addRequest(world, stc_ros::toEntityRequest(msg), {}, stc_ros::resolveMeshResource);
      stc_fuzz::require(world.entityCount() == before + 1, "accepted spawn did not add one entity");
    } catch (const stc::InputError&) {
      stc_fuzz::require(world.entityCount() == before, "rejected spawn changed the entity count");
    }
  }
  for (int tick = 0; tick < 3; ++tick) {
    const stc::TickReport report = world.step(1.0 / 60.0, stc::Budget::ofSphereTests(20000));
    stc_fuzz::checkWorldAfterStep(world, report);
  }
  return 0;
}
