#include "backend/optimization/gauss_newton_solver.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "backend/optimization/normal_equations.h"

namespace pldvo {

SolverSummary GaussNewtonSolver::Solve(LeastSquaresProblem* problem,
                                       const SolverIterationCallback& callback) const {
  SolverSummary summary;
  if (problem->residual_blocks().empty()) {
    summary.message = "no residual blocks";
    return summary;
  }
  // The normal equations at the current point and at a trial point. A trial step that follows
  // an accepted one is linearised in full: if it is accepted too, its normal equations are the
  // next iteration's and the cost functions are evaluated once for it, not twice. After a
  // rejection only the cost is evaluated: near the minimum rejections come in runs, and a
  // linearisation costs ~2.3x a cost evaluation (docs/tracking.md).
  NormalEquations current_equations(*problem);
  NormalEquations trial_equations(*problem);
  NormalEquations* equations = &current_equations;
  NormalEquations* trial = &trial_equations;
  if (equations->dimension() == 0) {
    summary.message = "no variable parameter blocks";
    return summary;
  }
  double cost = 0.0;
  if (!equations->Linearize(&cost)) {
    summary.message = "cost function evaluation failed at the initial point";
    return summary;
  }
  summary.initial_cost = cost;
  summary.final_cost = cost;
  if (callback) callback({0, cost, true});

  const int n = equations->dimension();
  Eigen::MatrixXd damped(n, n);
  Eigen::VectorXd delta(n);
  std::vector<double> backup;
  Eigen::LDLT<Eigen::MatrixXd> ldlt(n);
  double lambda = options_.initial_lambda;
  int consecutive_rejections = 0;
  bool linearize_trial = true;
  if (equations->gradient().lpNorm<Eigen::Infinity>() <= options_.gradient_tolerance) {
    summary.converged = true;
    summary.message = "gradient tolerance reached at the initial point";
    return summary;
  }
  summary.message = "iteration limit reached";
  while (summary.iterations < options_.max_iterations) {
    ++summary.iterations;
    damped = equations->hessian();
    if (lambda > 0.0) damped.diagonal() += lambda * equations->hessian().diagonal();
    ldlt.compute(damped);
    bool step_ok = ldlt.info() == Eigen::Success;
    if (step_ok) {
      delta = ldlt.solve(-equations->gradient());
      step_ok = delta.allFinite();
    }
    double new_cost = cost;
    bool accepted = false;
    if (step_ok) {
      const double x_norm = equations->ParameterNorm();
      if (delta.norm() <= options_.parameter_tolerance * (x_norm + options_.parameter_tolerance)) {
        --summary.iterations;  // the negligible step is not taken
        summary.converged = true;
        summary.message = "parameter tolerance reached";
        break;
      }
      // The decrease the linearised model predicts for this step (>= 0 for a positive
      // semi-definite damped system); when even that is negligible, more steps cannot help.
      const double model_decrease =
          -(equations->gradient().dot(delta) + 0.5 * delta.dot(equations->hessian() * delta));
      if (model_decrease <= options_.function_tolerance * cost) {
        --summary.iterations;
        summary.converged = true;
        summary.message = "predicted decrease below the function tolerance";
        break;
      }
      if (equations->ApplyStep(delta, &backup) &&
          (linearize_trial ? trial->Linearize(&new_cost) : problem->EvaluateCost(&new_cost)) &&
          std::isfinite(new_cost) && new_cost <= cost) {
        accepted = true;
      } else {
        equations->Restore(backup);
      }
    }
    if (!accepted) {
      linearize_trial = false;
      lambda = std::max(10.0 * lambda, options_.min_lambda);
      ++consecutive_rejections;
      if (callback) callback({summary.iterations, cost, false});
      if (options_.max_consecutive_rejections > 0 &&
          consecutive_rejections >= options_.max_consecutive_rejections) {
        // Where the Jacobian is only approximate, the floor of the cost along its directions
        // is reached: more damping only shortens the step.
        summary.converged = true;
        summary.message = "no decrease in max_consecutive_rejections damped steps";
        break;
      }
      if (lambda > options_.max_lambda) {
        // No damped step decreases the cost: we are at a minimum to numerical precision.
        summary.converged = true;
        summary.message = "no step decreases the cost (damping limit reached)";
        break;
      }
      continue;
    }
    ++summary.accepted_iterations;
    consecutive_rejections = 0;
    lambda = lambda / 10.0 < options_.min_lambda ? 0.0 : lambda / 10.0;
    const double decrease = (cost - new_cost) / cost;
    if (linearize_trial) {
      std::swap(equations, trial);
      cost = new_cost;
    } else if (!equations->Linearize(&cost)) {
      summary.message = "cost function evaluation failed";
      break;
    }
    linearize_trial = true;
    summary.final_cost = cost;
    if (callback) callback({summary.iterations, cost, true});
    if (decrease <= options_.function_tolerance) {
      summary.converged = true;
      summary.message = "function tolerance reached";
      break;
    }
    if (equations->gradient().lpNorm<Eigen::Infinity>() <= options_.gradient_tolerance) {
      summary.converged = true;
      summary.message = "gradient tolerance reached";
      break;
    }
  }
  return summary;
}

}  // namespace pldvo
