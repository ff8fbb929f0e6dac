// Ceres options shared by the windowed bundle adjustments (backend/edge_ba/, backend/windowed_ba/):
// Levenberg-Marquardt, silent, SuiteSparse when Ceres has it (Eigen's sparse algebra otherwise),
// and the linear solver a config names. Each caller adds its own elimination ordering.
#ifndef PLDVO_BACKEND_OPTIMIZATION_BUNDLE_ADJUSTMENT_OPTIONS_H_
#define PLDVO_BACKEND_OPTIMIZATION_BUNDLE_ADJUSTMENT_OPTIONS_H_

#include <ceres/solver.h>

#include "backend/optimization/ba_linear_solver.h"

namespace pldvo {

ceres::Solver::Options MakeBundleAdjustmentCeresOptions(BALinearSolver linear_solver,
                                                        int max_iterations,
                                                        double function_tolerance, int num_threads);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_BUNDLE_ADJUSTMENT_OPTIONS_H_
