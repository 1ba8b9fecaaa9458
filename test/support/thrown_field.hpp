// The field an InputError names, for tests of input checks.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <functional>
#include <string>

namespace stc {

// The field of the InputError `f` throws; "<no throw>" when it returns
// (other exceptions pass through, failing the test).
inline std::string thrownField(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.field();
  }
  return "<no throw>";
}

}  // namespace stc
