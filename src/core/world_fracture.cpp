// World's part of fracture (world_fracture.hpp): which bodies break this
// tick, their pieces' trees built inside the tick budget, and the pieces
// placed, weighed and set moving as the parent was (fracture.hpp).
#include "world_fracture.hpp"

#include "tick_context.hpp"
#include "world_parts.hpp"

#include <algorithm>
#include <string>

namespace stc {

// ---------------------------------------------------------------------------------
// World: its calls into the part

std::vector<EntityId> World::Parts::breakEntity(EntityId id, const Vec3& point, const Vec3& normal) {
  return fracture_->breakEntity(*world_, id, point, normal);
}

const std::vector<BrokenEntity>& World::broken() const { return parts_->fracture_->broken(); }

void World::Parts::fracture(TickContext& tick) {
  tick.time.now = fracture_->fracture(*world_, clock_, tick.time.now, tick.tick_end, tick.report);
}

void World::Parts::breakPending(TickContext& tick) {
  tick.time.now = fracture_->breakPending(*world_, clock_, tick.time.now, tick.tick_end, tick.report);
}

// ---------------------------------------------------------------------------------
// WorldFracture

std::vector<EntityId> WorldFracture::breakEntity(World& world, EntityId id, const Vec3& point, const Vec3& normal) {
  const auto found = world.indexOf(id);
  if (!found || world.bodies()[*found].is_static || !point.allFinite() || !(normal.norm() > 0.0)) return {};
  std::vector<VoxelPiece> pieces = piecesOf(world, *found, gridPlaneOf(world, *found, point, normal));
  return placePieces(world, *found, pieces);
}

SplitPlane WorldFracture::gridPlaneOf(const World& world, std::size_t index, const Vec3& point, const Vec3& normal) {
  const Pose& pose = world.bodies()[index].pose;
  const ShapeInfo& info = world.shape(world.bodyShapes()[index]);
  // The body frame is the grid frame moved to the centre of mass.
  const Quat to_body = pose.orientation.conjugate();
  return fracturePlane(to_body * (point - pose.position) + info.body_origin, to_body * normal, info.body_origin);
}

std::vector<VoxelPiece> WorldFracture::piecesOf(const World& world, std::size_t index, const SplitPlane& plane) {
  const VoxelShape& voxels = world.shape(world.bodyShapes()[index]).voxels;
  std::vector<VoxelPiece> pieces = splitVoxelShape(voxels, plane, world.config().fracture);
  if (pieces.size() == 1 && pieces[0].voxels == voxels.occupiedCount()) return {};
  if (world.entityCount() - 1 + pieces.size() > world.config().max_entities) return {};
  return pieces;
}

std::optional<ShapeId> WorldFracture::findPieceShape(const World& world, const VoxelShape& voxels, std::string* key) {
  // Content key; a clash with different voxels (never seen) gets a suffix.
  *key = pieceShapeKey(voxels);
  while (const auto same_key = world.findShape(*key)) {
    if (sameVoxels(world.shape(*same_key).voxels, voxels)) return same_key;
    *key += "'";
  }
  return std::nullopt;
}

std::vector<EntityId> WorldFracture::placePieces(World& world, std::size_t index, std::vector<VoxelPiece>& pieces) {
  if (pieces.empty()) return {};
  const WorldConfig& config = world.config();
  const BodyState parent = world.bodies()[index];  // copied: the arrays change below
  const ShapeInfo& info = world.shape(world.bodyShapes()[index]);  // deque: stays put as pieces are added
  const Mat3 r = parent.pose.orientation.toRotationMatrix();
  // The parent's density: the pieces' exact mass properties follow from it.
  const double density = 1.0 / (parent.inv_mass * info.unit_mass.mass);
  const double s = info.voxels.voxelSize();
  const std::string parent_name = world.bodyNames()[index];
  std::vector<EntitySpec> specs(pieces.size());
  int next_name = 0;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    std::string key;
    const auto found = findPieceShape(world, pieces[k].shape, &key);
    const ShapeId shape = found ? *found : world.addShape(key, std::move(pieces[k].shape));
    // The piece's centre of mass, from the parent's: its voxels stay where they were.
    const Vec3 offset =
        r * (pieces[k].offset.cast<double>() * s + world.shape(shape).body_origin - info.body_origin);
    EntitySpec& spec = specs[k];
    spec.shape = shape;
    spec.pose.position = parent.pose.position + offset;
    spec.pose.orientation = parent.pose.orientation;
    spec.linear_velocity = parent.linear_velocity + parent.angular_velocity.cross(offset);
    spec.angular_velocity = parent.angular_velocity;
    spec.density = density;
    spec.material = parent.material;
    spec.material.strength = pieceStrength(parent.material.strength, pieces[k].voxels,
                                           info.voxels.occupiedCount(), config.fracture.strength_exponent);
    if (!parent_name.empty()) {
      do {
        spec.name = parent_name + "/piece" + std::to_string(next_name++);
      } while (world.findByName(spec.name));
    }
    // A piece the limits would reject (its rim faster than max_speed, say)
    // keeps the body whole: nothing is removed that cannot be replaced.
    try {
      validateBodyInput(spec.pose, spec.linear_velocity, spec.angular_velocity, spec.density,
                        spec.material, config.limits);
    } catch (const InputError&) {
      return {};
    }
  }
  const EntityId id = world.entityIds()[index];
  BrokenEntity broken{id, parent_name, world.bodyShapes()[index], {}};
  world.removeEntity(id);
  for (const EntitySpec& spec : specs) broken.pieces.push_back(world.addEntity(spec));
  broken_.push_back(broken);
  return broken.pieces;
}

double WorldFracture::fracture(World& world, const SecondsClock& clock, double now, const Deadline& tick_end,
                               TickReport& report) {
  const std::vector<BodyState>& bodies = world.bodies();
  const std::vector<Contact>& contacts = world.contacts();
  bool breakable = false;
  for (const Contact& c : contacts) {
    breakable = breakable || bodies[c.index_a].material.strength > 0.0 ||
                bodies[c.index_b].material.strength > 0.0;
  }
  if (!breakable) return now;

  // Summed impulse on each body, and its hardest-hit contact: the impact point.
  hits_.assign(bodies.size(), BodyHits{});
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const Contact& c = contacts[i];
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
  // Each breaking body's plane, in its own frame (the dense indices and the
  // contacts go stale with the first break), queued after the breaks older
  // ticks had no time for.
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const BodyState& body = bodies[i];
    if (body.is_static || !(body.material.strength > 0.0) || !(hits_[i].impulse > body.material.strength)) continue;
    const EntityId id = world.entityIds()[i];
    const bool queued = std::any_of(pending_breaks_.begin(), pending_breaks_.end(),
                                    [id](const PendingBreak& p) { return p.id == id; });
    if (queued) continue;
    const Contact& c = contacts[hits_[i].hardest];
    pending_breaks_.push_back({id, gridPlaneOf(world, i, c.point, c.normal)});
  }
  breakQueued(world, clock, tick_end, false, report);
  const double end = clock();
  report.fracture.fracture_s += end - now;
  return end;
}

double WorldFracture::breakPending(World& world, const SecondsClock& clock, double now, const Deadline& tick_end,
                                   TickReport& report) {
  if (pending_breaks_.empty()) return now;
  // At the tick's start one tree only (and the breaks whose trees exist):
  // integrate and the broad phase that follow cannot be cut short, so more
  // trees wait for the tick's end, where the time left is known.
  breakQueued(world, clock, tick_end.isSet() ? Deadline(&clock, now) : tick_end, true, report);
  const double end = clock();
  report.fracture.fracture_s += end - now;
  return end;
}

// Oldest first. A break is made once all its pieces' trees exist (equal
// pieces share one); a missing tree is built when its estimated cost fits
// before the deadline, or, once, when asked (the queue always moves). The
// first break whose trees do not fit stops the walk: it and the rest wait.
void WorldFracture::breakQueued(World& world, const SecondsClock& clock, const Deadline& trees_until,
                                bool one_tree_anyway, TickReport& report) {
  std::size_t done = 0;
  for (; done < pending_breaks_.size(); ++done) {
    const PendingBreak& p = pending_breaks_[done];
    const auto index = world.indexOf(p.id);
    if (!index) continue;  // removed meanwhile
    std::vector<VoxelPiece> pieces = piecesOf(world, *index, p.plane);
    bool ready = true;
    for (const VoxelPiece& piece : pieces) {
      std::string key;
      if (findPieceShape(world, piece.shape, &key)) continue;
      if (!one_tree_anyway && !(tree_cost_.seconds(piece.voxels) <= trees_until.remaining())) {
        ready = false;
        break;
      }
      one_tree_anyway = false;
      const double start = clock();
      world.addShape(key, piece.shape);
      const double seconds = clock() - start;
      tree_cost_.record(piece.voxels, seconds);
      ++report.fracture.piece_trees;
      report.fracture.piece_tree_s += seconds;
    }
    if (!ready) break;
    if (!placePieces(world, *index, pieces).empty()) ++report.fracture.fractures;
  }
  pending_breaks_.erase(pending_breaks_.begin(), pending_breaks_.begin() + done);
  report.fracture.fractures_deferred = pending_breaks_.size();
}

}  // namespace stc
