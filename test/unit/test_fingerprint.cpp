// The behaviour's fingerprint: every built-in scene, 300 ticks, one hash of
// the bits of every body state, at 1 and 2 threads (unlimited budget) and at
// a sphere-test budget (1 thread). A change meant to keep behaviour (a
// refactor, a faster phase) must leave test/fingerprints.txt as it is; a
// change meant to alter it rewrites the file and says why in its commit:
//   STC_WRITE_FINGERPRINTS=1 build/devel/lib/sphere_tree_collision/test_fingerprint
// The bits are those of this project's build (-ffp-contract=off, x86-64 SSE2,
// Debian's libm), so another compiler or architecture may need its own file.
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>

namespace stc {
namespace {

constexpr const char* kFile = "test/fingerprints.txt";  // tests run from the package's root
constexpr int kTicks = 300;
constexpr int kEntities = 100;
constexpr int kSphereTests = 2000;  // a tick's budget in the budgeted run: most pairs stay unresolved

const SceneKind kScenes[] = {SceneKind::PackedBox, SceneKind::BouncingBox, SceneKind::Rockfall,
                             SceneKind::CornerDrift, SceneKind::CubeBox,     SceneKind::Pyramid};

// FNV-1a, 64 bits, over raw bytes.
class Fnv {
 public:
  void add(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      hash_ ^= bytes[i];
      hash_ *= 1099511628211ull;
    }
  }
  void add(double x) { add(&x, sizeof x); }
  void add(const Vec3& v) {
    for (int k = 0; k < 3; ++k) add(v[k]);
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 1469598103934665603ull;
};

std::uint64_t stateHash(const World& world) {
  Fnv fnv;
  for (std::size_t i = 0; i < world.entityCount(); ++i) {
    const EntityId id = world.entityIds()[i];
    fnv.add(&id, sizeof id);
    const BodyState& body = world.bodies()[i];
    fnv.add(body.pose.position);
    const Eigen::Vector4d q = body.pose.orientation.coeffs();
    for (int k = 0; k < 4; ++k) fnv.add(q[k]);
    fnv.add(body.linear_velocity);
    fnv.add(body.angular_velocity);
  }
  return fnv.value();
}

// The hash after kTicks ticks of `kind` at `threads`, budgeted or not.
std::string runFingerprint(SceneKind kind, int threads, bool budgeted) {
  SceneParams params;
  params.entities = kEntities;
  WorldConfig config;
  config.threads = threads;
  SceneWorld scene = makeSceneWorld(kind, params, config);
  const Budget budget = budgeted ? Budget::ofSphereTests(kSphereTests) : Budget::unlimited();
  for (int t = 0; t < kTicks; ++t) scene.world.step(scene.spec.dt, budget);
  std::ostringstream out;
  out << std::hex << stateHash(scene.world);
  return out.str();
}

std::string key(SceneKind kind, int threads, bool budgeted) {
  std::ostringstream out;
  out << toString(kind) << " threads=" << threads << " budget=" << (budgeted ? "sphere_tests" : "unlimited");
  return out.str();
}

std::map<std::string, std::string> readFingerprints() {
  std::map<std::string, std::string> known;
  std::ifstream in(kFile);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t colon = line.rfind(": ");
    if (colon != std::string::npos) known[line.substr(0, colon)] = line.substr(colon + 2);
  }
  return known;
}

TEST(Fingerprint, EveryBuiltInSceneGivesTheRecordedBits) {
  std::map<std::string, std::string> now;
  for (const SceneKind kind : kScenes) {
    const std::string one = runFingerprint(kind, 1, false);
    const std::string two = runFingerprint(kind, 2, false);
    EXPECT_EQ(one, two) << toString(kind) << ": 1 and 2 threads differ";
    now[key(kind, 1, false)] = one;
    now[key(kind, 2, false)] = two;
    now[key(kind, 1, true)] = runFingerprint(kind, 1, true);
  }
  const char* write = std::getenv("STC_WRITE_FINGERPRINTS");
  if (write != nullptr && std::strcmp(write, "1") == 0) {
    std::ofstream out(kFile);
    out << "# test_fingerprint: " << kTicks << " ticks of each built-in scene at " << kEntities
        << " entities, FNV-1a of every body's state bits.\n"
        << "# Rewrite only for a change meant to alter behaviour (see test/unit/test_fingerprint.cpp).\n";
    for (const auto& [k, v] : now) out << k << ": " << v << "\n";
    ASSERT_TRUE(static_cast<bool>(out)) << "could not write " << kFile;
    return;
  }
  const std::map<std::string, std::string> known = readFingerprints();
  ASSERT_FALSE(known.empty()) << kFile << " is missing or empty";
  for (const auto& [k, v] : now) {
    const auto found = known.find(k);
    ASSERT_NE(found, known.end()) << k << " is not recorded in " << kFile;
    EXPECT_EQ(found->second, v) << k << ": the behaviour changed (now " << v << ")";
  }
}

}  // namespace
}  // namespace stc
