// World's part of fracture: which bodies break this tick, and their pieces
// placed, weighed and set moving as the parent was (fracture.hpp).
#include "sphere_tree_collision/world.hpp"

#include <algorithm>
#include <string>

namespace stc {

std::vector<EntityId> World::breakEntity(EntityId id, const Vec3& point, const Vec3& normal) {
  const auto found = indexOf(id);
  if (!found || bodies_[*found].is_static || !point.allFinite() || !(normal.norm() > 0.0)) return {};
  const BodyState parent = bodies_[*found];  // copied: the arrays change below
  const ShapeInfo& info = shapes_[body_shapes_[*found]];  // deque: stays put as pieces are added
  const Mat3 r = parent.pose.orientation.toRotationMatrix();
  // The body frame is the grid frame moved to the centre of mass.
  const Vec3 point_grid = r.transpose() * (point - parent.pose.position) + info.body_origin;
  const SplitPlane plane = fracturePlane(point_grid, r.transpose() * normal, info.body_origin);
  std::vector<VoxelPiece> pieces = splitVoxelShape(info.voxels, plane, config_.fracture);
  if (pieces.size() == 1 && pieces[0].voxels == info.voxels.occupiedCount()) return {};
  if (ids_.size() - 1 + pieces.size() > config_.max_entities) return {};

  // The parent's density: the pieces' exact mass properties follow from it.
  const double density = 1.0 / (parent.inv_mass * info.unit_mass.mass);
  const double s = info.voxels.voxelSize();
  const std::string parent_name = names_[*found];
  std::vector<EntitySpec> specs(pieces.size());
  int next_name = 0;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    // Content key; a clash with different voxels (never seen) gets a suffix.
    std::string key = pieceShapeKey(pieces[k].shape);
    while (const auto same_key = findShape(key)) {
      if (sameVoxels(shapes_[*same_key].voxels, pieces[k].shape)) break;
      key += "'";
    }
    const ShapeId shape = addShape(key, std::move(pieces[k].shape));
    // The piece's centre of mass, from the parent's: its voxels stay where they were.
    const Vec3 offset = r * (pieces[k].offset.cast<double>() * s + shapes_[shape].body_origin - info.body_origin);
    EntitySpec& spec = specs[k];
    spec.shape = shape;
    spec.pose.position = parent.pose.position + offset;
    spec.pose.orientation = parent.pose.orientation;
    spec.linear_velocity = parent.linear_velocity + parent.angular_velocity.cross(offset);
    spec.angular_velocity = parent.angular_velocity;
    spec.density = density;
    spec.material = parent.material;
    if (!parent_name.empty()) {
      do {
        spec.name = parent_name + "/piece" + std::to_string(next_name++);
      } while (id_by_name_.count(spec.name) != 0);
    }
    // A piece the limits would reject (its rim faster than max_speed, say)
    // keeps the body whole: nothing is removed that cannot be replaced.
    try {
      validateBodyInput(spec.pose, spec.linear_velocity, spec.angular_velocity, spec.density,
                        spec.material, config_.limits);
    } catch (const InputError&) {
      return {};
    }
  }
  BrokenEntity broken{id, parent_name, body_shapes_[*found], {}};
  removeEntity(id);
  for (const EntitySpec& spec : specs) broken.pieces.push_back(addEntity(spec));
  broken_.push_back(broken);
  return broken.pieces;
}

double World::fracture(double now, const Deadline& tick_end, TickReport& report) {
  bool breakable = false;
  for (const Contact& c : contacts_) {
    breakable = breakable || bodies_[c.index_a].material.strength > 0.0 ||
                bodies_[c.index_b].material.strength > 0.0;
  }
  if (!breakable) return now;

  // Summed impulse on each body, and its hardest-hit contact: the impact point.
  hits_.assign(bodies_.size(), BodyHits{});
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    const Contact& c = contacts_[i];
    const double impulse = (c.normal_impulse * c.normal + c.friction_impulse).norm();
    for (const std::uint32_t body : {c.index_a, c.index_b}) {
      BodyHits& hits = hits_[body];
      hits.impulse += impulse;
      if (hits.hardest < 0 || impulse > hits.hardest_impulse) {
        hits.hardest_impulse = impulse;
        hits.hardest = static_cast<std::int32_t>(i);
      }
    }
  }
  // Where each breaking body is hit, in its own frame (the dense indices and
  // the contacts go stale with the first break), queued after the breaks
  // older ticks had no time for.
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const BodyState& body = bodies_[i];
    if (body.is_static || !(body.material.strength > 0.0) || !(hits_[i].impulse > body.material.strength)) continue;
    const EntityId id = ids_[i];
    const bool queued = std::any_of(pending_breaks_.begin(), pending_breaks_.end(),
                                    [id](const PendingBreak& p) { return p.id == id; });
    if (queued) continue;
    const Contact& c = contacts_[hits_[i].hardest];
    const Quat to_body = body.pose.orientation.conjugate();
    pending_breaks_.push_back({id, to_body * (c.point - body.pose.position), to_body * c.normal});
  }
  breakQueued(tick_end, false, report);
  const double end = clock_();
  report.fracture_s += end - now;
  return end;
}

double World::breakPending(double now, const Deadline& tick_end, TickReport& report) {
  if (pending_breaks_.empty()) return now;
  breakQueued(tick_end, true, report);
  const double end = clock_();
  report.fracture_s += end - now;
  return end;
}

// Oldest first, until the deadline (at least one when asked: the queue
// always moves); the rest wait for the next tick.
void World::breakQueued(const Deadline& tick_end, bool at_least_one, TickReport& report) {
  std::size_t done = 0;
  while (done < pending_breaks_.size() && ((at_least_one && done == 0) || !tick_end.passed())) {
    const PendingBreak& p = pending_breaks_[done++];
    const auto index = indexOf(p.id);
    if (!index) continue;  // removed meanwhile
    const Pose pose = bodies_[*index].pose;
    if (!breakEntity(p.id, pose.apply(p.point), pose.orientation * p.normal).empty()) ++report.fractures;
  }
  pending_breaks_.erase(pending_breaks_.begin(), pending_breaks_.begin() + done);
  report.fractures_deferred = pending_breaks_.size();
}

}  // namespace stc
