// One synchronous windowed edge bundle adjustment (docs/edge_ba.md): builds the problem
// (EdgeBAProblemBuilder) and solves it with Ceres' Levenberg-Marquardt. The default linear
// solver is SPARSE_SCHUR on SuiteSparse with the lines eliminated first (ParameterBlockOrdering:
// lines in group 0, poses in group 1), so each step factorises only the reduced camera matrix
// (6 x 6 blocks per free pose).
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_SOLVER_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_SOLVER_H_

#include <ceres/solver.h>

#include "backend/edge_ba/edge_ba_options.h"
#include "backend/edge_ba/edge_ba_problem_builder.h"
#include "backend/edge_ba/edge_ba_window.h"

namespace pldvo {

// Ceres options for a built problem: LM, the linear solver of `options` with the elimination
// ordering above, iterations, tolerance, threads, silent. SuiteSparse falls back to Eigen's
// sparse Cholesky when Ceres was built without it.
ceres::Solver::Options MakeEdgeBASolverOptions(const EdgeBAOptions& options,
                                               EdgeBAProblem* problem);

// Builds and solves the window; never throws on a degenerate window (success = false and a
// message), throws std::invalid_argument on invalid options or a malformed window. With
// options.line_depth_feedback, a successful solve also returns the optimised lines' marginal
// tangent covariances (ceres::Covariance, EdgeBAResultLine::tangent_covariance; covariance_ok
// false when that fails).
EdgeBAResult SolveEdgeBA(const EdgeBAWindow& window, const EdgeBAOptions& options);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_SOLVER_H_
