// Response (paper 3.5, 4), one header per part; this one includes them all:
//   response_options.hpp  what the response does (ResponseOptions, SolverKind)
//   shape_bounds.hpp      per-shape voxel boxes and reach of the tree nodes
//   interior_field.hpp    per-shape depth inside the voxels, and the way out
//   contact_builder.hpp   contacts from the intersecting sphere pairs of a PairTest
//   contact_solver.hpp    impulses, restitution, friction, position correction
//   continuous.hpp        the swept test that stops fast bodies at their first contact
//   physics.hpp           the World's integrate, sweep, contact and solve phases (StepContext)
// Everything but physics.hpp also works without a World, on flat arrays.
#pragma once

#include "contact_builder.hpp"
#include "contact_solver.hpp"
#include "continuous.hpp"
#include "interior_field.hpp"
#include "physics.hpp"
#include "shape_bounds.hpp"
#include "sphere_tree_collision/response_options.hpp"
