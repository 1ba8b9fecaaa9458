// Response options: names of the solver kinds and the checks of every field.
#include "sphere_tree_collision/response_options.hpp"

#include "sphere_tree_collision/types.hpp"

#include <cmath>

namespace stc {

SolverKind parseSolverKind(const std::string& name) {
  if (name == "sequential") return SolverKind::Sequential;
  if (name == "jacobi") return SolverKind::Jacobi;
  if (name == "soft") return SolverKind::Soft;
  throw InputError("solver", "unknown solver '" + name + "' (sequential | jacobi | soft)");
}

const char* toString(SolverKind kind) {
  switch (kind) {
    case SolverKind::Jacobi: return "jacobi";
    case SolverKind::Soft: return "soft";
    case SolverKind::Sequential: break;
  }
  return "sequential";
}

void validateResponseOptions(const ResponseOptions& o) {
  if (o.iterations < 1 || o.iterations > 1000) {
    throw InputError("response.iterations", "must be in [1, 1000]");
  }
  if (!(o.restitution_threshold >= 0.0 && std::isfinite(o.restitution_threshold))) {
    throw InputError("response.restitution_threshold", "must be finite and >= 0");
  }
  if (!(o.position_correction >= 0.0 && o.position_correction <= 1.0)) {
    throw InputError("response.position_correction", "must be in [0, 1]");
  }
  if (!(o.allowed_penetration >= 0.0 && std::isfinite(o.allowed_penetration))) {
    throw InputError("response.allowed_penetration", "must be finite and >= 0");
  }
  if (o.max_contacts_per_pair < 1 || o.max_contacts_per_pair > 16) {
    throw InputError("response.max_contacts_per_pair", "must be in [1, 16]");
  }
  if (o.solver_task_manifolds < 1) {
    throw InputError("response.solver_task_manifolds", "must be >= 1");
  }
  if (!(o.sweep_threshold > 0.0 && std::isfinite(o.sweep_threshold))) {
    throw InputError("response.sweep_threshold", "must be finite and > 0");
  }
  if (o.substeps < 1 || o.substeps > 64) {
    throw InputError("response.substeps", "must be in [1, 64]");
  }
  if (!(o.contact_hertz >= 0.0 && std::isfinite(o.contact_hertz))) {
    throw InputError("response.contact_hertz", "must be finite and >= 0 (0: a quarter of the substep rate)");
  }
  if (!(o.contact_damping_ratio > 0.0 && std::isfinite(o.contact_damping_ratio))) {
    throw InputError("response.contact_damping_ratio", "must be finite and > 0");
  }
  if (!(o.max_push_speed > 0.0 && std::isfinite(o.max_push_speed))) {
    throw InputError("response.max_push_speed", "must be finite and > 0");
  }
  if (!(o.reuse_tolerance >= 0.0 && o.reuse_tolerance <= 1.0)) {
    throw InputError("response.reuse_tolerance", "must be in [0, 1]");
  }
}

}  // namespace stc
