// How many of the narrow phase's leaf sphere pairs are voxel boxes that touch
// (docs/bullet.md, "What the cube pile's leaf pairs are"). A leaf sphere bulges
// past its voxel box (radius sqrt(3)/2 of a voxel against a half side of 1/2),
// so on a face resting on a face each leaf overlaps the 3 x 3 leaves across
// it, and the contact builder keeps the deep ones only. This counts, after
// --ticks ticks of a built-in scene at an unlimited budget, the leaf pairs of
// the colliding pair tests, and of them those whose two voxel boxes (the
// ShapeBounds boxes of the leaves, oriented with their bodies) overlap by the
// separating-axis test, exactly and with a margin of --margin times the
// smaller half side of the two boxes. Then, on the same pairs, a depth-first
// model of the tree test (TreeWalk) with and without that box test at every
// node pair (the box of the node's leaves' boxes): how many sphere tests and
// leaf pairs a box test in the narrow phase would leave.
//
// Usage: bench_leaf_boxes [--scene cube_box] [--bodies 10000] [--ticks 150] [--margin 0.1]
//          [--smoke]  (200 bodies, 3 ticks: that the bench runs, scripts/bench_smoke.sh)
#include "bench_args.hpp"
#include "pair_test.hpp"
#include "shape_bounds.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_map>

namespace {

using namespace stc;

struct Options {
  SceneKind scene = SceneKind::CubeBox;
  int bodies = 10000;
  int ticks = 150;
  double margin = 0.1;
};

Options parse(int argc, char** argv) {
  Options o;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string a = args.flag();
    if (a == "--scene") o.scene = parseScene(args.required());
    else if (a == "--bodies") o.bodies = std::stoi(args.required());
    else if (a == "--ticks") o.ticks = std::stoi(args.required());
    else if (a == "--margin") o.margin = std::stod(args.required());
    else if (a == "--smoke") o.bodies = 200, o.ticks = 3;
    else throw InputError(a, "unknown option (see the comment at the top of bench/leaf_boxes.cpp)");
  }
  if (o.bodies < 1) throw InputError("--bodies", "must be >= 1");
  if (o.ticks < 1) throw InputError("--ticks", "must be >= 1");
  if (!(o.margin >= 0.0)) throw InputError("--margin", "must be >= 0");
  return o;
}

// A node's box in the world.
struct WorldBox {
  Vec3 centre, half;
  Mat3 axes;  // columns: the box's axes (its body's)
};

// Separating-axis test of two oriented boxes: the 3 + 3 face axes and the 9
// edge cross products; `gap` is how far apart they may be along an axis and
// still count as overlapping.
bool boxesOverlap(const WorldBox& a, const WorldBox& b, double gap) {
  const Mat3 r = a.axes.transpose() * b.axes;  // b's axes in a's frame
  const Vec3 t = a.axes.transpose() * (b.centre - a.centre);
  const Mat3 abs_r = r.cwiseAbs().array() + 1e-12;  // parallel edges: their cross product is no axis
  for (int i = 0; i < 3; ++i) {
    if (std::abs(t[i]) > a.half[i] + b.half.dot(abs_r.row(i).transpose()) + gap) return false;
  }
  for (int j = 0; j < 3; ++j) {
    if (std::abs(t.dot(r.col(j))) > a.half.dot(abs_r.col(j)) + b.half[j] + gap) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double reach_a = a.half[i1] * abs_r(i2, j) + a.half[i2] * abs_r(i1, j);
      const double reach_b = b.half[j1] * abs_r(i, j2) + b.half[j2] * abs_r(i, j1);
      if (std::abs(t[i2] * r(i1, j) - t[i1] * r(i2, j)) > reach_a + reach_b + gap) return false;
    }
  }
  return true;
}

// The box of a node's leaves' boxes in the world (ShapeBounds::leaves_centre
// and leaves_half; a leaf's own voxel box for a leaf).
WorldBox nodeBox(const PairBody& body, const ShapeBounds& bounds, std::int32_t node) {
  const Mat3 axes = body.pose->orientation.toRotationMatrix();
  const auto i = static_cast<std::size_t>(node);
  return WorldBox{body.pose->position + axes * bounds.leaves_centre[i], bounds.leaves_half[i], axes};
}

// A depth-first model of a pair's sphere-tree test (not PairTest's level by
// level schedule): a touching node pair opens the node that is not a leaf,
// the larger when neither is, and tests its children against the other
// node. With `boxes`, a touching node pair whose nodes' boxes are apart is
// not opened (and a leaf pair not counted). Counts sphere tests, box tests and leaf pairs.
struct TreeWalk {
  const PairBody& a;
  const PairBody& b;
  const ShapeBounds& bounds_a;
  const ShapeBounds& bounds_b;
  bool boxes;
  long tests = 0, leaf_pairs = 0, box_tests = 0;

  bool spheresTouch(std::int32_t na, std::int32_t nb) {
    ++tests;
    const SphereNode& sa = a.tree->node(na);
    const SphereNode& sb = b.tree->node(nb);
    const double reach = sa.radius + sb.radius;
    return (a.pose->apply(sa.centre) - b.pose->apply(sb.centre)).squaredNorm() <= reach * reach;
  }
  void walk(std::int32_t na, std::int32_t nb) {  // na, nb touch
    box_tests += boxes ? 1 : 0;
    if (boxes && !boxesOverlap(nodeBox(a, bounds_a, na), nodeBox(b, bounds_b, nb), 0.0)) return;
    const SphereNode& sa = a.tree->node(na);
    const SphereNode& sb = b.tree->node(nb);
    const bool leaf_a = sa.child_count == 0, leaf_b = sb.child_count == 0;
    if (leaf_a && leaf_b) {
      ++leaf_pairs;
      return;
    }
    const bool open_a = !leaf_a && (leaf_b || sa.radius >= sb.radius);
    const SphereNode& opened = open_a ? sa : sb;
    for (std::int32_t c = opened.first_child; c < opened.first_child + opened.child_count; ++c) {
      if (open_a ? spheresTouch(c, nb) : spheresTouch(na, c)) open_a ? walk(c, nb) : walk(na, c);
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!stc_bench::parseFlags("bench_leaf_boxes", parse, argc, argv, opt)) return 2;
  SceneParams params;
  params.entities = opt.bodies;
  SceneWorld scene = makeSceneWorld(opt.scene, params);
  World& world = scene.world;
  for (int t = 0; t < opt.ticks; ++t) world.step(scene.spec.dt, Budget::unlimited());

  // The shapes' boxes, by tree (a pair test knows its bodies' trees).
  std::unordered_map<const SphereTree*, ShapeBounds> bounds;
  for (ShapeId s = 0; s < static_cast<ShapeId>(world.shapeCount()); ++s) {
    const ShapeInfo& shape = world.shape(s);
    bounds.emplace(&shape.tree, makeShapeBounds(shape.tree, &shape.voxels, shape.body_origin));
  }
  long colliding = 0, leaf_pairs = 0, overlapping = 0, within_margin = 0;
  long model_tests[2] = {0, 0}, model_leaves[2] = {0, 0}, model_box_tests = 0;  // the tree walk without / with the box test
  for (std::size_t k = 0; k < world.pairCount(); ++k) {
    const PairTest& test = pairTests(world)[k];
    if (test.status() != PairStatus::Colliding) continue;
    ++colliding;
    const ShapeBounds& bounds_a = bounds.at(test.bodyA().tree);
    const ShapeBounds& bounds_b = bounds.at(test.bodyB().tree);
    for (int with_boxes = 0; with_boxes < 2; ++with_boxes) {
      TreeWalk w{test.bodyA(), test.bodyB(), bounds_a, bounds_b, with_boxes == 1};
      if (w.spheresTouch(0, 0)) w.walk(0, 0);
      model_tests[with_boxes] += w.tests;
      model_leaves[with_boxes] += w.leaf_pairs;
      model_box_tests += w.box_tests;
    }
    for (const SpherePair& p : test.lastPairs()) {
      const WorldBox a = nodeBox(test.bodyA(), bounds_a, p.a);
      const WorldBox b = nodeBox(test.bodyB(), bounds_b, p.b);
      const double gap = opt.margin * std::min(a.half.minCoeff(), b.half.minCoeff());
      ++leaf_pairs;
      overlapping += boxesOverlap(a, b, 0.0) ? 1 : 0;
      within_margin += boxesOverlap(a, b, gap) ? 1 : 0;
    }
  }
  const double leaves = std::max(1.0, static_cast<double>(leaf_pairs));
  std::printf("%s %d bodies, tick %d: %ld colliding pairs, %ld leaf pairs (%.1f a pair), %zu contacts (%.1f a pair)\n",
              toString(opt.scene), opt.bodies, opt.ticks, colliding, leaf_pairs,
              leaf_pairs / std::max(1.0, static_cast<double>(colliding)), world.contacts().size(),
              world.contacts().size() / std::max(1.0, static_cast<double>(colliding)));
  std::printf("leaf pairs whose voxel boxes overlap: %.1f %%; within %.2f of a half side: %.1f %%\n",
              100.0 * overlapping / leaves, opt.margin, 100.0 * within_margin / leaves);
  const double pairs = std::max(1.0, static_cast<double>(colliding));
  std::printf("depth-first model of the same pairs' tests: %.1f sphere tests and %.1f leaf pairs a pair; "
              "with the box test at every node pair: %.1f and %.1f (%.0f %% and %.0f %%), and %.1f box tests\n",
              model_tests[0] / pairs, model_leaves[0] / pairs, model_tests[1] / pairs, model_leaves[1] / pairs,
              100.0 * model_tests[1] / std::max(1L, model_tests[0]), 100.0 * model_leaves[1] / std::max(1L, model_leaves[0]), model_box_tests / pairs);
  return 0;
}
