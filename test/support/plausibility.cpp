#include "plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace stc::truth {

double deepestInStatic(const World& world, std::size_t mover) {
  const std::vector<BodyState>& bodies = world.bodies();
  const BodyState& m = bodies[mover];
  const ShapeInfo& ms = world.shape(world.bodyShapes()[mover]);
  const VoxelShape& mv = ms.voxels;
  const double vs = mv.voxelSize();
  double deepest = 0.0;
  for (std::size_t s = 0; s < bodies.size(); ++s) {
    const BodyState& st = bodies[s];
    if (!st.is_static) continue;
    const ShapeInfo& ss = world.shape(world.bodyShapes()[s]);
    const Vec3 half = 0.5 * ss.voxels.extent();
    const Vec3 box_centre = st.pose.position + st.pose.orientation * (half - ss.body_origin);
    if ((box_centre - m.pose.position).norm() > half.norm() + ms.bounding_radius) continue;
    const Mat3 rs = st.pose.orientation.toRotationMatrix();
    for (int k = 0; k < mv.nz(); ++k) {
      for (int j = 0; j < mv.ny(); ++j) {
        for (int i = 0; i < mv.nx(); ++i) {
          if (!mv.occupied(i, j, k)) continue;
          const Vec3 p = m.pose.position + m.pose.orientation * (Vec3(i + 0.5, j + 0.5, k + 0.5) * vs - ms.body_origin);
          const Vec3 q = rs.transpose() * (p - box_centre);
          if (std::abs(q.x()) > half.x() || std::abs(q.y()) > half.y() || std::abs(q.z()) > half.z()) continue;
          deepest = std::max(deepest, half.z() - q.z() + 0.5 * vs);
        }
      }
    }
  }
  return deepest;
}

PlausibilityCheck::PlausibilityCheck(const World& world, const SceneSpec& spec)
    : bounds_(spec.bounds), movers_(spec.movers) {
  // A fall from the highest mover (along gravity) to the lowest corner of the
  // bounds, starting at the fastest start speed; without gravity, that speed.
  const Vec3 g = world.config().gravity;
  const Vec3 up = g.norm() > 0.0 ? Vec3(-g.normalized()) : Vec3::Zero();
  double top = -std::numeric_limits<double>::infinity(), v0 = 0.0;
  for (EntityId id : movers_) {
    const BodyState& b = world.bodies()[*world.indexOf(id)];
    top = std::max(top, up.dot(b.pose.position));
    v0 = std::max(v0, b.linear_velocity.norm());
    track_[id] = Track{b.pose.position, b.linear_velocity};
  }
  double bottom = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? bounds_.max.x() : bounds_.min.x(), (c & 2) ? bounds_.max.y() : bounds_.min.y(),
                      (c & 4) ? bounds_.max.z() : bounds_.min.z());
    bottom = std::min(bottom, up.dot(corner));
  }
  f_.movers = movers_.size();
  f_.fall_speed = movers_.empty() ? 0.0 : std::sqrt(v0 * v0 + 2.0 * g.norm() * std::max(0.0, top - bottom));
}

void PlausibilityCheck::tick(const World& world, double dt) {
  for (EntityId id : movers_) {
    const auto index = world.indexOf(id);
    if (!index) continue;  // removed: counted outside at the end
    const BodyState& b = world.bodies()[*index];
    Track& k = track_[id];
    // Held still by its island's level (island_levels.hpp), its time did not
    // pass this tick: its windows are of the ticks it was stepped (of every
    // tick, for a mover never held).
    if (world.responseLevel(id) != ResponseLevel::Held) {
      k.stored += k.velocity.norm();  // the velocity this tick moved it with
      k.real += (b.pose.position - k.position).norm() / dt;
      ++k.ticks;
    }
    k.position = b.pose.position;
    k.velocity = b.linear_velocity;
    const double speed = b.linear_velocity.norm();
    f_.max_speed = std::max(f_.max_speed, speed);
    k.too_fast = k.too_fast || !(speed <= f_.fall_speed);
    if (k.ticks < kPlausibilityWindow) continue;
    const double stored = k.stored / kPlausibilityWindow, real = k.real / kPlausibilityWindow;
    const double excess = std::abs(stored - real) - (0.1 * real + 0.05);
    f_.worst_window_excess = std::max(f_.worst_window_excess, excess);
    ++f_.windows;
    if (!(excess <= 0.0)) ++f_.bad_windows;
    k.stored = k.real = 0.0;
    k.ticks = 0;
  }
}

Plausibility PlausibilityCheck::finish(const World& world) const {
  Plausibility f = f_;
  f.plate_thickness = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < world.bodies().size(); ++i) {
    if (world.bodies()[i].is_static) {
      f.plate_thickness = std::min(f.plate_thickness, world.shape(world.bodyShapes()[i]).voxels.extent().z());
    }
  }
  for (const auto& [id, k] : track_) f.too_fast += k.too_fast ? 1 : 0;
  std::vector<double> sinks;  // in voxels
  double height = 0.0;
  for (EntityId id : movers_) {
    const auto index = world.indexOf(id);
    if (!index) {
      ++f.outside;  // left the world, or quarantined
      continue;
    }
    const BodyState& b = world.bodies()[*index];
    f.asleep += world.isSleeping(id) ? 1 : 0;
    height += b.pose.position.z();
    if (!(allFinite(b.pose.position) && b.pose.orientation.coeffs().allFinite() && allFinite(b.linear_velocity) &&
          allFinite(b.angular_velocity))) {
      ++f.non_finite;
      continue;
    }
    if (!bounds_.contains(b.pose.position)) ++f.outside;
    const double sink = deepestInStatic(world, *index);
    const double voxels = sink / world.shape(world.bodyShapes()[*index]).voxels.voxelSize();
    sinks.push_back(voxels);
    f.max_sink = std::max(f.max_sink, sink);
    f.max_sink_voxels = std::max(f.max_sink_voxels, voxels);
    if (voxels > 1.0) ++f.sunk;
  }
  std::sort(sinks.begin(), sinks.end());
  if (!sinks.empty()) f.sink_p99_voxels = sinks[static_cast<std::size_t>(0.99 * static_cast<double>(sinks.size() - 1))];
  f.mean_height = movers_.empty() ? 0.0 : height / static_cast<double>(movers_.size());
  return f;
}

std::string describe(const Plausibility& f) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "NaN %zu, outside %zu of %zu; fastest %.2f m/s (a fall allows %.2f), %zu too fast; "
                "%zu of %zu windows of %d ticks off stored/real by > 10 %% + 0.05 m/s (worst excess %.3f m/s); "
                "into static plates p99 %.2f voxels, deepest %.2f (%.3f m; plates %.3f m thick), %zu > 1 voxel; "
                "asleep %zu; mean height %.2f m",
                f.non_finite, f.outside, f.movers, f.max_speed, f.fall_speed, f.too_fast, f.bad_windows, f.windows,
                kPlausibilityWindow, f.worst_window_excess, f.sink_p99_voxels, f.max_sink_voxels, f.max_sink,
                f.plate_thickness, f.sunk, f.asleep, f.mean_height);
  return buf;
}

}  // namespace stc::truth
