#include "backend/windowed_ba/windowed_ba_solver.h"

#include <ceres/ordered_groups.h>
#include <ceres/problem.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "backend/optimization/bundle_adjustment_options.h"
#include "backend/optimization/ceres_solver.h"
#include "backend/optimization/gauss_newton_solver.h"
#include "backend/windowed_ba/marginalization.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

ceres::Solver::Options MakeWindowedBACeresOptions(const WindowedBAOptions& options,
                                                  const WindowedBAProblem& problem) {
  ceres::Solver::Options solver_options =
      MakeBundleAdjustmentCeresOptions(options.linear_solver, options.max_iterations,
                                       options.function_tolerance, options.num_threads);
  // Inverse depths (group 0) eliminated first; every other block, constant ones included, after
  // them in a group of its own, in the order they were added. Ceres orders the elements of a
  // group by address, and the poses and brightness live in separate arrays whose relative
  // addresses differ between runs: one group for all of them made the reduced camera system's
  // column order, and with it the solution's rounding, differ from run to run.
  const std::vector<double*> eliminated = problem.problem.EliminatedBlocks();
  if (!eliminated.empty()) {
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    int next_group = 1;
    for (const LeastSquaresProblem::ParameterBlock& block : problem.problem.parameter_blocks()) {
      ordering->AddElementToGroup(block.values,
                                  block.eliminated && !block.constant ? 0 : next_group++);
    }
    solver_options.linear_solver_ordering = ordering;
  }
  return solver_options;
}

SolverSummary SolveWindowedBAProblem(const WindowedBAOptions& options, WindowedBAProblem* problem) {
  SolverSummary summary;
  if (problem->problem.residual_blocks().empty() || problem->points.empty()) {
    summary.message = "no points with observations in the window";
    return summary;
  }
  if (options.solver == WindowedBASolver::kGaussNewton) {
    SolverOptions solver_options;
    solver_options.type = SolverOptions::Type::kGaussNewton;
    solver_options.max_iterations = options.max_iterations;
    solver_options.function_tolerance = options.function_tolerance;
    // Damped from the first step, as Ceres' LM with its initial trust region radius 1e4 is
    // (mu = 1 / radius on the scaled diagonal): an undamped first step can leave the basin the
    // photometric rows define.
    solver_options.initial_lambda = 1e-4;
    return GaussNewtonSolver(solver_options).Solve(&problem->problem);
  }
  std::unique_ptr<ceres::Problem> ceres_problem = problem->problem.ToCeresProblem();
  const ceres::Solver::Options solver_options = MakeWindowedBACeresOptions(options, *problem);
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, ceres_problem.get(), &ceres_summary);
  return SummarizeCeresSolve(ceres_summary);
}

WindowedBAResult RunWindowedBA(const WindowedBAWindow& window, const WindowedBAOptions& options) {
  const auto build_start = std::chrono::steady_clock::now();
  WindowedBAProblem problem =
      MakeWindowedBAProblemBuilder(options.problem_builder, options)->Build(window);
  WindowedBAResult result;
  result.build_seconds = SecondsSince(build_start);
  result.num_photometric_rows = problem.num_photometric_rows;
  result.num_line_rows = problem.num_line_rows;
  result.num_outlier_targets = problem.num_outlier_targets;
  result.num_prior_keyframes = problem.num_prior_keyframes;
  const auto solve_start = std::chrono::steady_clock::now();
  result.summary = SolveWindowedBAProblem(options, &problem);
  result.solve_seconds = SecondsSince(solve_start);
  for (size_t k = 0; k < problem.keyframe_indices.size(); ++k) {
    WindowedBAResultKeyframe keyframe;
    keyframe.id = window.keyframes[problem.keyframe_indices[k]].id;
    keyframe.cam_from_world = PoseFromParameters(problem.poses[k].data());
    keyframe.brightness = {problem.brightness[k][0], problem.brightness[k][1]};
    result.keyframes.push_back(keyframe);
  }
  for (size_t i = 0; i < problem.points.size(); ++i) {
    const WindowedBAProblemPoint& point = problem.points[i];
    result.points.push_back({window.keyframes[problem.keyframe_indices[point.host]].id,
                             point.point_index, problem.idepths[i]});
  }
  // The next window drops the oldest keyframe of a full one.
  const int n = static_cast<int>(problem.keyframe_indices.size());
  if (options.marginalize && n == options.window && std::isfinite(result.summary.final_cost)) {
    const auto marginalize_start = std::chrono::steady_clock::now();
    std::vector<int> ids;
    for (const WindowedBAResultKeyframe& keyframe : result.keyframes) ids.push_back(keyframe.id);
    WindowedBAPrior prior;
    if (MarginalizeOldestKeyframe(ids, &problem, &prior)) {
      result.prior = std::make_shared<const WindowedBAPrior>(std::move(prior));
    }
    result.marginalize_seconds = SecondsSince(marginalize_start);
  }
  return result;
}

}  // namespace pldvo
