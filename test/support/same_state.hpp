// Two worlds in the same state bit for bit: every double of every body and
// contact compared with ==, none within a tolerance.
#pragma once

#include "same_bits.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace stc {

inline ::testing::AssertionResult sameState(const World& x, const World& y) {
  if (x.entityCount() != y.entityCount()) return ::testing::AssertionFailure() << "entity counts differ";
  for (std::size_t i = 0; i < x.entityCount(); ++i) {
    if (x.entityIds()[i] != y.entityIds()[i] || !sameBits(x.bodies()[i], y.bodies()[i])) {
      return ::testing::AssertionFailure() << "body " << i << " differs";
    }
  }
  const std::vector<Contact>& cx = x.contacts();
  const std::vector<Contact>& cy = y.contacts();
  if (cx.size() != cy.size()) return ::testing::AssertionFailure() << "contact counts " << cx.size() << " " << cy.size();
  for (std::size_t k = 0; k < cx.size(); ++k) {
    const Contact& a = cx[k];
    const Contact& b = cy[k];
    if (a.a != b.a || a.b != b.b || a.point != b.point || a.normal != b.normal || a.separation != b.separation ||
        a.gap_bound != b.gap_bound || a.sphere_bound != b.sphere_bound || a.resolved != b.resolved || a.normal_impulse != b.normal_impulse ||
        a.friction_impulse != b.friction_impulse) {
      return ::testing::AssertionFailure() << "contact " << k << " differs";
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace stc
