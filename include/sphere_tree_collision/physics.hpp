// The World's physics: integrate and respond, keeping what lasts between
// ticks (warm-start impulses by entity id, sweep data, scratch).
#pragma once

#include "sphere_tree_collision/contact_builder.hpp"
#include "sphere_tree_collision/contact_solver.hpp"
#include "sphere_tree_collision/continuous.hpp"
#include "sphere_tree_collision/response_options.hpp"
#include "sphere_tree_collision/shape_bounds.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace stc {

struct ShapeInfo;  // world.hpp

struct PhysicsReport {
  SweepStats sweep;
  SolveStats solve;
};

class Physics {
 public:
  // Voxels, tree and body origin of a shape id; called once per new shape.
  using ShapeOf = std::function<const ShapeInfo&(std::uint32_t shape)>;

  // Tick phase 1: positions, velocities (gravity), and which bodies are fast.
  void integrate(std::vector<BodyState>& bodies, const std::vector<std::uint32_t>& body_shapes,
                 const ShapeOf& shape_of, const Vec3& gravity, const ResponseOptions& options,
                 double dt);
  // After integrate: fast bodies need swept boxes in the broad phase, from
  // their start pose of the tick to their pose now.
  bool isFast(std::size_t body) const {
    return body < sweep_scratch_.fast.size() && sweep_scratch_.fast[body] != 0;
  }
  const Pose& startPose(std::size_t body) const { return start_[body]; }
  // Tick phase 2b, after the broad phase: sweep of the fast bodies against
  // their broad-phase partners pair_bodies[0..count) (sweepFastBodies).
  void sweep(std::vector<BodyState>& bodies, const std::vector<std::array<std::uint32_t, 2>>& pair_bodies,
             std::size_t count, const ResponseOptions& options);
  // Tick phase 4: contacts of tests[0..count) (pair_bodies: dense indices of
  // each test's bodies; the same pairs the sweep saw), plus the sweep's hit
  // for a pair whose test gave no contact, then impulses when options.enabled,
  // within `budget`.
  void respond(const std::vector<PairTest>& tests, std::size_t count,
               const std::vector<std::array<std::uint32_t, 2>>& pair_bodies,
               const std::vector<double>& priorities, bool accept_unresolved,
               const std::vector<std::uint32_t>& body_shapes, const ShapeOf& shape_of,
               std::vector<BodyState>& bodies, const ResponseOptions& options, double dt,
               std::vector<Contact>& contacts, const SolveBudget& budget = SolveBudget{});
  const PhysicsReport& lastReport() const { return report_; }
  void forget() { solver_.forget(); }

 private:
  const ShapeBounds& boundsOf(std::uint32_t shape, const ShapeOf& shape_of);

  ContactBuilder builder_;
  ContactSolver solver_;
  double gravity_speed_ = 0.0;  // |g| dt of the last integrate
  std::vector<ShapeBounds> bounds_;  // by shape id, built on first use
  std::vector<Pose> start_;
  std::vector<const ShapeBounds*> body_bounds_;
  SweepScratch sweep_scratch_;
  std::vector<std::int32_t> sweep_hit_of_pair_;  // body whose sweep hit that pair, or -1
  PhysicsReport report_;
};

}  // namespace stc
