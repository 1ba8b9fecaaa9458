// Names of the enum options, as parameters and scenes spell them. One table per
// enum, so parsing and printing cannot drift apart.
#include "pair_test.hpp"
#include "scheduler.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/world.hpp"

#include <array>
#include <utility>

namespace stc {
namespace {

template <typename Enum, std::size_t N>
Enum parseName(const std::array<std::pair<Enum, const char*>, N>& table, const std::string& name,
               const char* field) {
  std::string allowed;
  for (const auto& [value, text] : table) {
    if (name == text) return value;
    allowed += allowed.empty() ? "" : ", ";
    allowed += text;
  }
  throw InputError(field, "unknown value '" + name + "' (expected one of: " + allowed + ")");
}

template <typename Enum, std::size_t N>
const char* nameOf(const std::array<std::pair<Enum, const char*>, N>& table, Enum value) {
  for (const auto& [v, text] : table) {
    if (v == value) return text;
  }
  return "?";
}

const std::array<std::pair<SphereFit, const char*>, 2> kSphereFits{{
    {SphereFit::Paper, "paper"}, {SphereFit::Tight, "tight"}}};
const std::array<std::pair<SchedulerKind, const char*>, 4> kSchedulers{{
    {SchedulerKind::RoundRobin, "round_robin"},
    {SchedulerKind::Sequential, "sequential"},
    {SchedulerKind::PerceptualSequential, "perceptual_sequential"},
    {SchedulerKind::PriorityQueues, "priority_queues"}}};
const std::array<std::pair<UnresolvedPolicy, const char*>, 2> kPolicies{{
    {UnresolvedPolicy::Accept, "accept"}, {UnresolvedPolicy::Reject, "reject"}}};
const std::array<std::pair<BoxMode, const char*>, 3> kBoxModes{{
    {BoxMode::Auto, "auto"}, {BoxMode::FixedCube, "fixed"}, {BoxMode::Dynamic, "dynamic"}}};
const std::array<std::pair<PairStatus, const char*>, 3> kStatuses{{
    {PairStatus::Unresolved, "unresolved"},
    {PairStatus::Colliding, "colliding"},
    {PairStatus::Separate, "separate"}}};

}  // namespace

SphereFit parseSphereFit(const std::string& name) { return parseName(kSphereFits, name, "sphere_fit"); }
const char* toString(SphereFit fit) { return nameOf(kSphereFits, fit); }
SchedulerKind parseScheduler(const std::string& name) { return parseName(kSchedulers, name, "scheduler"); }
const char* toString(SchedulerKind kind) { return nameOf(kSchedulers, kind); }
UnresolvedPolicy parseUnresolvedPolicy(const std::string& name) {
  return parseName(kPolicies, name, "unresolved_policy");
}
const char* toString(UnresolvedPolicy policy) { return nameOf(kPolicies, policy); }
BoxMode parseBoxMode(const std::string& name) { return parseName(kBoxModes, name, "box_mode"); }
const char* toString(BoxMode mode) { return nameOf(kBoxModes, mode); }
const char* toString(PairStatus s) { return nameOf(kStatuses, s); }

}  // namespace stc
