#include "backend/optimization/ceres_solver.h"

#include <ceres/ceres.h>

namespace pldvo {
namespace {

class ForwardingCallback : public ceres::IterationCallback {
 public:
  explicit ForwardingCallback(const SolverIterationCallback& callback) : callback_(callback) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    SolverIteration iteration;
    iteration.iteration = summary.iteration;
    iteration.cost = summary.cost;
    iteration.step_accepted = summary.step_is_successful;
    callback_(iteration);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const SolverIterationCallback& callback_;
};

}  // namespace

SolverSummary CeresSolver::Solve(LeastSquaresProblem* problem,
                                 const SolverIterationCallback& callback) const {
  SolverSummary result;
  if (problem->residual_blocks().empty()) {
    result.message = "no residual blocks";
    return result;
  }
  std::unique_ptr<ceres::Problem> ceres_problem = problem->ToCeresProblem();
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type =
      options_.ceres_linear_solver == SolverOptions::CeresLinearSolver::kDenseQr
          ? ceres::DENSE_QR
          : ceres::DENSE_NORMAL_CHOLESKY;
  options.num_threads = options_.num_threads;
  options.max_num_iterations = options_.max_iterations;
  options.function_tolerance = options_.function_tolerance;
  options.gradient_tolerance = options_.gradient_tolerance;
  options.parameter_tolerance = options_.parameter_tolerance;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ForwardingCallback forwarding(callback);
  if (callback) {
    options.update_state_every_iteration = true;
    options.callbacks.push_back(&forwarding);
  }
  ceres::Solver::Summary summary;
  ceres::Solve(options, ceres_problem.get(), &summary);
  return SummarizeCeresSolve(summary);
}

SolverSummary SummarizeCeresSolve(const ceres::Solver::Summary& summary) {
  SolverSummary result;
  // Ceres lists iteration 0 (the initial state) in summary.iterations.
  result.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  result.accepted_iterations = summary.num_successful_steps;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.message = summary.message;
  return result;
}

}  // namespace pldvo
