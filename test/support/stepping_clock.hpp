// A fake clock for budget tests: it reads 0, step, 2 step, ..., so every read
// costs `step` seconds of fake time and a time budget gives the same cut on
// any machine under any load.
#pragma once

#include "sphere_tree_collision/budget.hpp"

#include <memory>

namespace stc {

inline SecondsClock steppingClock(double step) {
  auto now = std::make_shared<double>(0.0);
  return [now, step] {
    const double t = *now;
    *now += step;
    return t;
  };
}

}  // namespace stc
