// A World made from a bad config is refused with an InputError naming the
// field: the one check every config test makes.
#pragma once

#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <string>

namespace stc {

inline ::testing::AssertionResult worldRefuses(const WorldConfig& config, const std::string& field) {
  try {
    World w(config);
  } catch (const InputError& e) {
    if (e.field() == field) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "refused naming " << e.field() << " instead of " << field << ": " << e.what();
  }
  return ::testing::AssertionFailure() << "a World was made: " << field << " was not refused";
}

}  // namespace stc
