// Faces of static bodies' voxel boxes that other static bodies cover (static_cover.hpp).
#include "static_cover.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>

namespace stc {
namespace {

// The points tested lie this fraction of the body's voxel outside a face: well
// inside a flush neighbour's voxel, clear of rounding at the shared plane.
constexpr double kOutside = 0.25;
// At most this many points along each side of a face (large inner nodes).
constexpr int kMaxSamplesPerSide = 16;

struct Placed {
  std::size_t index = 0;
  const CoverShape* shape = nullptr;
  Mat3 rot;
  Vec3 pos;
  double radius = 0.0;  // bound of the shape about the body origin
};

bool occupiedAt(const Placed& body, const Vec3& world) {
  const Vec3 grid = body.rot.transpose() * (world - body.pos) + body.shape->body_origin;
  const VoxelShape& v = *body.shape->voxels;
  const Vec3 cell = grid / v.voxelSize();
  if (!(cell.minCoeff() >= 0.0)) return false;  // also NaN
  const int i = static_cast<int>(cell.x()), j = static_cast<int>(cell.y()), k = static_cast<int>(cell.z());
  return i < v.nx() && j < v.ny() && k < v.nz() && v.occupied(i, j, k);
}

// The faces of one node's box of `body` that its own voxels or `neighbours`' cover.
std::uint8_t nodeMask(const Placed& body, std::int32_t node, const std::vector<const Placed*>& neighbours) {
  const ShapeBounds& bounds = *body.shape->bounds;
  const std::size_t n = static_cast<std::size_t>(node);
  const double voxel = body.shape->voxels->voxelSize();
  const Vec3 centre = bounds.tree->node(node).centre + bounds.box_offset[n];  // body frame
  const Vec3 half = bounds.box_half[n];
  std::uint8_t mask = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int nu = std::clamp(static_cast<int>(std::lround(2.0 * half[u] / voxel)), 1, kMaxSamplesPerSide);
    const int nv = std::clamp(static_cast<int>(std::lround(2.0 * half[v] / voxel)), 1, kMaxSamplesPerSide);
    for (const bool positive : {true, false}) {
      const double side = positive ? 1.0 : -1.0;
      bool all = true;
      for (int a = 0; a < nu && all; ++a) {
        for (int b = 0; b < nv && all; ++b) {
          Vec3 local = centre;
          local[axis] += side * (half[axis] + kOutside * voxel);
          local[u] += half[u] * ((2.0 * a + 1.0) / nu - 1.0);
          local[v] += half[v] * ((2.0 * b + 1.0) / nv - 1.0);
          const Vec3 world = body.rot * local + body.pos;
          all = occupiedAt(body, world) ||
                std::any_of(neighbours.begin(), neighbours.end(),
                            [&world](const Placed* other) { return occupiedAt(*other, world); });
        }
      }
      if (all) mask |= faceBit(axis, positive);
    }
  }
  return mask;
}

}  // namespace

namespace {
const char* const kFaceNames[] = {"+x", "-x", "+y", "-y", "+z", "-z"};  // faceBit order
}  // namespace

std::vector<std::string> faceNames(std::uint8_t mask) {
  std::vector<std::string> names;
  for (int bit = 0; bit < 6; ++bit) {
    if ((mask & (1u << bit)) != 0) names.emplace_back(kFaceNames[bit]);
  }
  return names;
}

std::uint8_t parseFaces(const std::vector<std::string>& names) {
  const auto& kNames = kFaceNames;
  std::uint8_t mask = 0;
  for (const std::string& name : names) {
    const auto* found = std::find(std::begin(kNames), std::end(kNames), name);
    if (found == std::end(kNames)) {
      throw InputError("closed_faces", "unknown face '" + name + "' (expected +x, -x, +y, -y, +z or -z)");
    }
    mask |= static_cast<std::uint8_t>(1u << (found - std::begin(kNames)));
  }
  return mask;
}

void StaticCover::add(const BodyState& body, std::uint8_t closed_faces) {
  masks_.emplace_back();
  poses_.push_back(body.pose);
  is_static_.push_back(body.is_static ? 1 : 0);
  closed_.push_back(body.is_static ? closed_faces : 0);
  dirty_.push_back(body.is_static ? 1 : 0);
  if (body.is_static) stale_ = true;
}

void StaticCover::remove(std::size_t index, std::size_t last) {
  assert(index <= last && last + 1 == masks_.size());
  if (is_static_[index] != 0) {  // its neighbours' faces it covered are open again
    removed_.push_back(poses_[index].position);
    stale_ = true;
  }
  if (index != last) {
    masks_[index] = std::move(masks_[last]);
    poses_[index] = poses_[last];
    is_static_[index] = is_static_[last];
    closed_[index] = closed_[last];
    dirty_[index] = dirty_[last];
  }
  masks_.pop_back();
  poses_.pop_back();
  is_static_.pop_back();
  closed_.pop_back();
  dirty_.pop_back();
}

void StaticCover::clear() {
  masks_.clear();
  poses_.clear();
  is_static_.clear();
  closed_.clear();
  dirty_.clear();
  removed_.clear();
  stale_ = false;
}

bool StaticCover::update(const std::vector<BodyState>& bodies, const std::vector<std::uint32_t>& body_shapes,
                         const std::vector<CoverShape>& shapes) {
  assert(bodies.size() == masks_.size());
  bool stale = stale_;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (is_static_[i] == 0) continue;
    const Pose& p = bodies[i].pose;
    if (p.position != poses_[i].position || p.orientation.coeffs() != poses_[i].orientation.coeffs()) {
      dirty_[i] = 1;  // moved: its old neighbours are found through its old place
      removed_.push_back(poses_[i].position);
      stale = true;
    }
  }
  if (!stale) return false;
  stale_ = false;

  // Statics whose bounding spheres' x-ranges overlap are candidates; a sweep along x.
  std::vector<Placed> statics;
  double largest = 0.0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    poses_[i] = bodies[i].pose;
    if (is_static_[i] == 0) continue;
    const CoverShape& shape = shapes[body_shapes[i]];
    if (shape.voxels == nullptr || shape.bounds == nullptr) continue;
    Placed p;
    p.index = i;
    p.shape = &shape;
    p.rot = bodies[i].pose.orientation.toRotationMatrix();
    p.pos = bodies[i].pose.position;
    p.radius = shape.bounds->bound_radius + shape.voxels->voxelSize();
    largest = std::max(largest, p.radius);
    statics.push_back(p);
  }
  std::sort(statics.begin(), statics.end(),
            [](const Placed& a, const Placed& b) { return a.pos.x() - a.radius < b.pos.x() - b.radius; });
  std::vector<std::vector<const Placed*>> neighbours(statics.size());
  for (std::size_t a = 0; a < statics.size(); ++a) {
    for (std::size_t b = a + 1; b < statics.size(); ++b) {
      if (statics[b].pos.x() - statics[b].radius > statics[a].pos.x() + statics[a].radius) break;
      if ((statics[a].pos - statics[b].pos).norm() > statics[a].radius + statics[b].radius) continue;
      neighbours[a].push_back(&statics[b]);
      neighbours[b].push_back(&statics[a]);
    }
  }
  // Only what changed is measured again: a static body added or moved, and
  // every static body near it or near where one was removed or moved from
  // (a scene of 340 tiles costs 12 ms whole; one tile spawned into it, its
  // own and its few neighbours' masks).
  std::vector<std::uint8_t> redo(statics.size(), 0);
  for (std::size_t a = 0; a < statics.size(); ++a) {
    if (dirty_[statics[a].index] == 0) continue;
    redo[a] = 1;
    for (const Placed* n : neighbours[a]) redo[static_cast<std::size_t>(n - statics.data())] = 1;
  }
  for (const Vec3& gone : removed_) {
    for (std::size_t a = 0; a < statics.size(); ++a) {
      if ((statics[a].pos - gone).norm() <= statics[a].radius + largest) redo[a] = 1;
    }
  }
  removed_.clear();
  for (std::size_t a = 0; a < statics.size(); ++a) {
    const Placed& body = statics[a];
    dirty_[body.index] = 0;
    if (redo[a] == 0) continue;
    const std::uint8_t closed = closed_[body.index];
    const std::size_t nodes = body.shape->bounds->tree->nodes().size();
    std::vector<std::uint8_t> mask(nodes, closed);
    bool any = closed != 0;
    for (std::size_t n = 0; n < nodes; ++n) {
      mask[n] |= nodeMask(body, static_cast<std::int32_t>(n), neighbours[a]);
      any = any || mask[n] != 0;
    }
    masks_[body.index].clear();
    if (any) masks_[body.index] = std::move(mask);
  }
  return true;
}

}  // namespace stc
