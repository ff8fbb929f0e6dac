// Solving one window of photometric + line bundle adjustment (docs/windowed_ba.md) with either
// solver on the same LeastSquaresProblem:
//   ceres         Levenberg-Marquardt on ToCeresProblem() with the linear solver of the
//                 options (default SPARSE_SCHUR on SuiteSparse, Eigen's sparse Cholesky when
//                 Ceres lacks it), the inverse depths eliminated first (ordering group 0) and
//                 the poses and brightness forming the reduced camera system (group 1);
//   gauss_newton  the hand-written GaussNewtonSolver (backend/optimization), which eliminates the
//                 same inverse-depth blocks by Schur complement (they are marked eliminated).
// Both evaluate the same cost functions and update through the same manifolds.
#ifndef PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_SOLVER_H_
#define PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_SOLVER_H_

#include <ceres/solver.h>

#include <memory>
#include <vector>

#include "backend/optimization/solver.h"
#include "backend/windowed_ba/windowed_ba_options.h"
#include "backend/windowed_ba/windowed_ba_problem_builder.h"
#include "backend/windowed_ba/windowed_ba_window.h"

namespace pldvo {

// Ceres options for a built problem (the ceres path above): LM, iterations, tolerance, threads,
// silent.
ceres::Solver::Options MakeWindowedBACeresOptions(const WindowedBAOptions& options,
                                                  const WindowedBAProblem& problem);

// Solves `problem` in place with options.solver. An empty problem returns converged = false
// and a message.
SolverSummary SolveWindowedBAProblem(const WindowedBAOptions& options, WindowedBAProblem* problem);

struct WindowedBAResultKeyframe {
  int id = -1;
  SE3 cam_from_world;
  AffineBrightness brightness;
};
struct WindowedBAResultPoint {
  int keyframe_id = -1;  // host
  int point_index = -1;  // into the host's WindowedBAKeyframe::points
  double idepth = 0.0;   // refined
};
struct WindowedBAResult {
  long sequence = -1;  // WindowedBundleAdjuster::Submit's number (-1: solved directly)
  SolverSummary summary;
  std::vector<WindowedBAResultKeyframe> keyframes;  // the window's keyframes, oldest first
  std::vector<WindowedBAResultPoint> points;        // the points that entered the problem
  int num_photometric_rows = 0;
  int num_line_rows = 0;
  int num_outlier_targets = 0;  // WindowedBAProblem::num_outlier_targets
  double build_seconds = 0.0;
  double solve_seconds = 0.0;
  // With WindowedBAOptions::marginalize and a full window: the prior for the next window (its
  // oldest keyframe marginalised), else null. num_prior_keyframes: the keyframes this window's
  // own prior constrained (0: none).
  std::shared_ptr<const WindowedBAPrior> prior;
  int num_prior_keyframes = 0;
  double marginalize_seconds = 0.0;
};

// Builds the window with the registered builder options.problem_builder and solves it. Throws
// std::invalid_argument on invalid options or a malformed window.
WindowedBAResult RunWindowedBA(const WindowedBAWindow& window, const WindowedBAOptions& options);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_SOLVER_H_
