// Physical limits and the quarantine: finite-but-absurd input is rejected by
// field and limit; a body that leaves the limits during a tick is removed at
// its end, named, and the rest of the world goes on exactly as without it.
#include "sphere_tree_collision/world.hpp"

#include "world_refuses.hpp"

#include <gtest/gtest.h>

#include <cfloat>
#include <limits>
#include <string>

namespace stc {
namespace {

struct Fixture {
  World world;
  ShapeId cube;
  explicit Fixture(const WorldConfig& config = WorldConfig{}) : world(config) {
    cube = world.addShape("cube", makePreset("cube", PresetParams{4, 0.05, 1}));
  }
  EntitySpec spec(const Vec3& position, const std::string& name = "") const {
    EntitySpec s;
    s.shape = cube;
    s.pose.position = position;
    s.name = name;
    return s;
  }
};

// The error names `field` and mentions `limit`; nothing was added.
void expectRejected(World& w, const EntitySpec& spec, const std::string& field, const std::string& limit) {
  const std::size_t before = w.entityCount();
  try {
    w.addEntity(spec);
    ADD_FAILURE() << "accepted a bad " << field;
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), field);
    EXPECT_NE(std::string(e.what()).find(limit), std::string::npos) << e.what();
  }
  EXPECT_EQ(w.entityCount(), before);
}

TEST(Limits, FiniteButAbsurdInputIsRejectedNamingFieldAndLimit) {
  Fixture f;
  EntitySpec s = f.spec(Vec3(1e300, 0, 0));
  expectRejected(f.world, s, "pose.position", "world_extent");
  s = f.spec(Vec3(0, 0, 10000.5));
  expectRejected(f.world, s, "pose.position", "world_extent");
  s = f.spec(Vec3::Zero());
  s.linear_velocity = Vec3(1e308, 0, 0);
  expectRejected(f.world, s, "linear_velocity", "max_speed");
  s.linear_velocity = Vec3(600, 600, 0);  // |v| = 849 < 1000: fine per axis, fine in norm
  EXPECT_NO_THROW(f.world.addEntity(s));
  s.linear_velocity = Vec3(800, 800, 0);  // |v| = 1131
  expectRejected(f.world, s, "linear_velocity", "max_speed");
  s = f.spec(Vec3::Zero());
  s.angular_velocity = Vec3(0, 1e308, 0);
  expectRejected(f.world, s, "angular_velocity", "max_spin");
  for (double density : {5e-324, 1e-310, DBL_MIN, 1e-4, 1e7}) {
    s = f.spec(Vec3::Zero());
    s.density = density;
    expectRejected(f.world, s, "density", "min_density");
  }
  s = f.spec(Vec3::Zero());
  s.material.friction = 11.0;
  expectRejected(f.world, s, "material.friction", "max_friction");
  s.material.friction = 0.5;
  s.material.restitution = 1.0 + 1e-12;
  expectRejected(f.world, s, "material.restitution", "[0, 1]");
}

TEST(Limits, LimitsGravityAndResponseAreCheckedWhenTheWorldIsMade) {
  WorldConfig config;
  config.gravity = Vec3(0, 0, -1e308);
  EXPECT_TRUE(worldRefuses(config, "gravity"));
  config = WorldConfig{};
  config.limits.max_speed = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(worldRefuses(config, "max_speed"));
  config = WorldConfig{};
  config.limits.min_density = 10.0;
  config.limits.max_density = 1.0;
  EXPECT_TRUE(worldRefuses(config, "min_density"));
  // The response's options too, as World::setResponse checks them.
  config = WorldConfig{};
  config.response.iterations = 0;
  EXPECT_TRUE(worldRefuses(config, "response.iterations"));
  config.response.iterations = 15;
  config.response.max_push_speed = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(worldRefuses(config, "response.max_push_speed"));
}

TEST(Limits, ARunawayBodyIsQuarantinedByNameAndTheRestGoesOnUntouched) {
  // Two far-apart bodies; in the first world one of them blows up.
  Fixture a, b;
  for (Fixture* f : {&a, &b}) {
    EntitySpec calm = f->spec(Vec3(0, 0, 0), "calm");
    calm.linear_velocity = Vec3(0.1, 0, 0);
    calm.angular_velocity = Vec3(0, 0, 0.5);
    f->world.addEntity(calm);
  }
  const EntityId runaway = a.world.addEntity(a.spec(Vec3(50, 0, 0), "runaway"));
  a.world.step(0.01, Budget{});
  b.world.step(0.01, Budget{});

  const std::size_t index = *a.world.indexOf(runaway);
  a.world.bodies()[index].linear_velocity.x() = std::numeric_limits<double>::quiet_NaN();  // a solver blow-up
  const TickReport report = a.world.step(0.01, Budget{});
  b.world.step(0.01, Budget{});
  ASSERT_EQ(a.world.quarantined().size(), 1u);
  EXPECT_EQ(a.world.quarantined()[0].id, runaway);
  EXPECT_EQ(a.world.quarantined()[0].name, "runaway");
  EXPECT_EQ(a.world.quarantined()[0].reason, Quarantine::NonFinite);
  EXPECT_STREQ(toString(Quarantine::NonFinite), "non-finite state");
  EXPECT_EQ(report.bodies.quarantined, 1u);
  EXPECT_EQ(report.bodies.left_world, 0u);
  EXPECT_EQ(report.bodies.entities, 1u);
  EXPECT_FALSE(a.world.findByName("runaway"));
  // The calm body moved exactly as in the world that never had a runaway.
  const BodyState& calm_a = a.world.bodies()[*a.world.indexOf(*a.world.findByName("calm"))];
  const BodyState& calm_b = b.world.bodies()[0];
  EXPECT_EQ(calm_a.pose.position, calm_b.pose.position);
  EXPECT_EQ(calm_a.pose.orientation.coeffs(), calm_b.pose.orientation.coeffs());
  EXPECT_EQ(calm_a.linear_velocity, calm_b.linear_velocity);

  a.world.step(0.01, Budget{});
  EXPECT_TRUE(a.world.quarantined().empty()) << "the list is of the last step only";
}

TEST(Limits, SpeedAndSpinBeyondTheLimitsAreQuarantined) {
  Fixture f;
  const EntityId fast = f.world.addEntity(f.spec(Vec3(0, 0, 0)));
  const EntityId spun = f.world.addEntity(f.spec(Vec3(10, 0, 0)));
  f.world.bodies()[*f.world.indexOf(fast)].linear_velocity = Vec3(2000, 0, 0);
  f.world.bodies()[*f.world.indexOf(spun)].angular_velocity = Vec3(0, 0, 2000);
  const TickReport report = f.world.step(1e-4, Budget{});
  EXPECT_EQ(report.bodies.quarantined, 2u);
  EXPECT_EQ(f.world.entityCount(), 0u);
  for (const QuarantinedEntity& q : f.world.quarantined()) {
    EXPECT_EQ(q.reason, q.id == fast ? Quarantine::TooFast : Quarantine::TooSpun);
  }
}

TEST(Limits, ABodyFallingOutOfTheWorldIsRemovedAsLeftTheWorld) {
  WorldConfig config;
  config.gravity = Vec3(0, 0, -9.81);
  config.limits.world_extent = 20.0;
  Fixture f(config);
  EntitySpec floor = f.spec(Vec3(5, 0, -1), "floor");
  floor.is_static = true;
  f.world.addEntity(floor);
  f.world.addEntity(f.spec(Vec3(0, 0, 0), "faller"));
  // Free fall to z = -20 takes sqrt(2 * 20 / 9.81) = 2.02 s: by 3 s it has left.
  std::size_t left = 0;
  for (int tick = 0; tick < 300; ++tick) {
    const TickReport r = f.world.step(0.01, Budget{});
    left += r.bodies.left_world;
    EXPECT_EQ(r.bodies.quarantined, 0u);
    for (const QuarantinedEntity& q : f.world.quarantined()) {
      EXPECT_EQ(q.name, "faller");
      EXPECT_EQ(q.reason, Quarantine::LeftWorld);
      EXPECT_GT(tick, 190) << "not before it is 20 m down";
    }
  }
  EXPECT_EQ(left, 1u);
  EXPECT_EQ(f.world.entityCount(), 1u) << "the static floor stays";
  EXPECT_TRUE(f.world.findByName("floor"));
}

}  // namespace
}  // namespace stc
