#include "sphere_tree_collision/ros/rockfall_spawner.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/param_reading.hpp"

#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/SpawnEntity.h>

#include <cmath>

namespace stc_ros {
namespace {

using stc::InputError;

// The built-in rockfall scene with 0.4 m rocks: ravine floor through (0, 0,
// 5.07) sloping down +x at 25 degrees, 2.4 m wide. Drop above its upper part.
const stc::Vec3 kRegionMin(0.6, -0.7, 5.6);
const stc::Vec3 kRegionMax(3.0, 0.7, 6.4);
const stc::Vec3 kDownhill(std::cos(25.0 * M_PI / 180.0), 0.0, -std::sin(25.0 * M_PI / 180.0));

}  // namespace

RockfallSpawner::RockfallSpawner(ros::NodeHandle nh, ros::NodeHandle pnh) {
  const double rate = positiveParam(pnh, "rate", 2.0);
  region_min_ = vec3Param(pnh, "region_min").value_or(kRegionMin);
  region_max_ = vec3Param(pnh, "region_max").value_or(kRegionMax);
  if ((region_max_ - region_min_).minCoeff() < 0.0) throw InputError("region_max", "must be >= region_min");
  direction_ = vec3Param(pnh, "direction").value_or(kDownhill);
  if (!(direction_.norm() > 0.0)) throw InputError("direction", "must not be zero");
  direction_.normalize();
  speed_ = paramOr(pnh, "speed", speed_);
  if (!(speed_ >= 0.0) || !std::isfinite(speed_)) throw InputError("speed", "must be finite and >= 0");
  size_ = positiveParam(pnh, "size", size_);
  resolution_ = intParamIn(pnh, "resolution", resolution_, 2, 64);
  shape_count_ = intParamIn(pnh, "shape_count", shape_count_, 1, 1000);
  max_rocks_ = intParamIn(pnh, "max_rocks", max_rocks_, 1, 1000000);
  count_ = static_cast<std::uint64_t>(intParamIn(pnh, "count", 0, 0, 100000000));  // 0: drops for ever
  density_ = positiveParam(pnh, "density", density_);
  restitution_ = paramOr(pnh, "restitution", restitution_);
  friction_ = paramOr(pnh, "friction", friction_);  // the world validates these, by name
  strength_ = paramOr(pnh, "strength", strength_);  // N s; 0: rocks never break
  seed_ = static_cast<std::uint32_t>(paramOr(pnh, "seed", 1));
  random_.seed(seed_);

  spawn_ = nh.advertise<sphere_tree_collision::SpawnEntity>("spawn", 100);
  despawn_ = nh.advertise<sphere_tree_collision::Despawn>("despawn", 100);
  timer_ = nh.createSteadyTimer(ros::WallDuration(1.0 / rate), [this](const ros::SteadyTimerEvent&) { drop(); });
  ROS_INFO("rockfall_spawner: %.2f rocks/s, at most %d alive", rate, max_rocks_);
}

void RockfallSpawner::drop() {
  if (spawn_.getNumSubscribers() == 0) return;  // no world yet: nothing to drop into
  if (count_ > 0 && dropped_ >= count_) return;  // all dropped: the pile comes to rest
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const stc::Vec3 at = region_min_ + (region_max_ - region_min_).cwiseProduct(stc::Vec3(unit(random_), unit(random_), unit(random_)));
  // A uniformly random rotation from three uniforms (Shoemake).
  const double u1 = unit(random_), u2 = 2.0 * M_PI * unit(random_), u3 = 2.0 * M_PI * unit(random_);
  const stc::Quat rotation(std::sqrt(u1) * std::cos(u3), std::sqrt(1 - u1) * std::sin(u2),
                           std::sqrt(1 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));

  sphere_tree_collision::SpawnEntity m;
  m.name = "rock_" + std::to_string(dropped_);
  m.preset = "rock";
  m.resolution = static_cast<std::uint32_t>(resolution_);
  m.seed = seed_ * 1000 + static_cast<std::uint32_t>(dropped_ % static_cast<std::uint64_t>(shape_count_));
  m.voxel_size = size_ / resolution_;
  m.pose = toPoseMsg(stc::Pose{at, rotation});
  m.twist.linear = toVector3Msg(speed_ * direction_);
  m.twist.angular = toVector3Msg(stc::Vec3(unit(random_) - 0.5, unit(random_) - 0.5, unit(random_) - 0.5) * 4.0);
  m.density = density_;
  m.restitution = restitution_;
  m.friction = friction_;
  m.strength = strength_;
  const float shade = static_cast<float>(0.45 + 0.25 * unit(random_));
  m.color.r = shade + 0.1f;
  m.color.g = shade;
  m.color.b = shade - 0.1f;
  m.color.a = 1.0f;
  spawn_.publish(m);
  live_.push_back(m.name);
  ++dropped_;

  while (static_cast<int>(live_.size()) > max_rocks_) {
    sphere_tree_collision::Despawn d;
    d.name = live_.front();
    despawn_.publish(d);
    live_.pop_front();
  }
}

}  // namespace stc_ros
