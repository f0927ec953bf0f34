#pragma once

// An optimized solve for SUNDIALS' dense direct linear solver.
//
// Debian 12 builds SUNDIALS 6.4.1 without optimization (see serial_vector_ops.h); its dense
// triangular solves, one per Newton iteration of every step that uses a Jacobian (BDF, and
// Adams with the model's linearization), were 1.7% of `mbid update`. The solver object keeps
// SUNDIALS' factorization and data; only its solve is replaced by the same substitutions in the
// same order, so the results are the same bits (tests/simulation/dense_solve_test.cc).
// Private to simulation/.

#include <sundials/sundials_linearsolver.h>

namespace mbid::simulation::internal {

// Replaces the solve of `solver`, made by SUNLinSol_Dense.
void UseOptimizedDenseSolve(SUNLinearSolver solver);

}  // namespace mbid::simulation::internal
