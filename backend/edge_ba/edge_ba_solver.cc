#include "backend/edge_ba/edge_ba_solver.h"

#include <ceres/covariance.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>

#include <chrono>
#include <map>
#include <memory>
#include <stdexcept>

#include "backend/optimization/bundle_adjustment_options.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The marginal tangent covariances of the variable line blocks of the solved problem, by block
// address; false when ceres::Covariance fails (rank-deficient Jacobian).
bool LineCovariances(const std::vector<double*>& lines, ceres::Problem* problem,
                     std::map<const double*, Eigen::Matrix4d>* covariances) {
  ceres::Covariance::Options options;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (const double* line : lines) blocks.emplace_back(line, line);
  if (!covariance.Compute(blocks, problem)) return false;
  for (const double* line : lines) {
    Eigen::Matrix<double, 4, 4, Eigen::RowMajor> block;
    if (!covariance.GetCovarianceBlockInTangentSpace(line, line, block.data())) return false;
    if (!block.allFinite()) return false;
    (*covariances)[line] = block;
  }
  return true;
}

}  // namespace

ceres::Solver::Options MakeEdgeBASolverOptions(const EdgeBAOptions& options,
                                               EdgeBAProblem* problem) {
  ceres::Solver::Options solver_options =
      MakeBundleAdjustmentCeresOptions(options.linear_solver, options.max_iterations,
                                       options.function_tolerance, options.num_threads);
  // Lines (group 0) are eliminated first; poses (group 1) form the reduced camera system. Every
  // parameter block of the problem must be in the ordering, constant ones included.
  const std::vector<double*> lines = problem->VariableLineBlocks();
  if (!lines.empty()) {
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (const LeastSquaresProblem::ParameterBlock& block : problem->problem.parameter_blocks()) {
      const bool is_line = block.size == 6;
      ordering->AddElementToGroup(block.values, is_line && !block.constant ? 0 : 1);
    }
    solver_options.linear_solver_ordering = ordering;
  }
  return solver_options;
}

EdgeBAResult SolveEdgeBA(const EdgeBAWindow& window, const EdgeBAOptions& options) {
  const auto build_start = std::chrono::steady_clock::now();
  EdgeBAProblem problem = EdgeBAProblemBuilder(options).Build(window);
  EdgeBAResult result;
  std::map<const double*, Eigen::Matrix4d> line_covariances;
  result.build_seconds = SecondsSince(build_start);
  result.num_residuals = problem.num_pixel_residuals;
  for (EdgeBALineStatus status : problem.line_status) {
    result.num_optimized_lines += status == EdgeBALineStatus::kOptimized;
    result.num_fixed_lines += status == EdgeBALineStatus::kFixed;
    result.num_dropped_lines += status == EdgeBALineStatus::kDropped;
  }

  if (problem.NumVariableTangentParameters() == 0 || problem.problem.residual_blocks().empty()) {
    result.message = "nothing to optimise (no free pose or line with usable observations)";
  } else {
    const auto solve_start = std::chrono::steady_clock::now();
    std::unique_ptr<ceres::Problem> ceres_problem = problem.problem.ToCeresProblem();
    const ceres::Solver::Options solver_options = MakeEdgeBASolverOptions(options, &problem);
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, ceres_problem.get(), &summary);
    result.solve_seconds = SecondsSince(solve_start);
    result.success = summary.IsSolutionUsable();
    result.message = summary.message;
    result.iterations = static_cast<int>(summary.iterations.size()) - 1;
    result.initial_cost = summary.initial_cost;
    result.final_cost = summary.final_cost;
    if (!result.success) {
      // Keep the input estimates.
      problem = EdgeBAProblemBuilder(options).Build(window);
    } else if (options.line_depth_feedback && !problem.VariableLineBlocks().empty()) {
      const auto covariance_start = std::chrono::steady_clock::now();
      result.covariance_ok =
          LineCovariances(problem.VariableLineBlocks(), ceres_problem.get(), &line_covariances);
      result.covariance_seconds = SecondsSince(covariance_start);
      if (!result.covariance_ok) line_covariances.clear();
    }
  }

  for (size_t w = 0; w < problem.keyframe_indices.size(); ++w) {
    EdgeBAResultKeyframe keyframe;
    keyframe.id = window.keyframes[problem.keyframe_indices[w]].id;
    keyframe.cam_from_world = PoseFromParameters(problem.poses[w].data());
    keyframe.fixed = problem.pose_fixed[w];
    result.keyframes.push_back(keyframe);
  }
  std::map<int, const EdgeBALine*> listed;
  for (const EdgeBALine& input : window.lines) listed[input.id] = &input;
  for (size_t i = 0; i < problem.line_ids.size(); ++i) {
    const auto listed_it = listed.find(problem.line_ids[i]);
    // A dropped line that was not listed has no estimate to return.
    if (problem.line_status[i] == EdgeBALineStatus::kDropped && listed_it == listed.end()) continue;
    EdgeBAResultLine line;
    line.line.id = problem.line_ids[i];
    line.status = problem.line_status[i];
    const double* values = problem.lines[i].data();
    line.line.point_in_world = Eigen::Vector3d(values[0], values[1], values[2]);
    line.line.direction_in_world = Eigen::Vector3d(values[3], values[4], values[5]).normalized();
    line.line.anchored = listed_it != listed.end() && listed_it->second->anchored;
    const auto covariance_it = line_covariances.find(values);
    if (line.status == EdgeBALineStatus::kOptimized && covariance_it != line_covariances.end()) {
      line.has_covariance = true;
      line.tangent_covariance = covariance_it->second;
    }
    result.lines.push_back(line);
  }
  return result;
}

}  // namespace pldvo
