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
namespace {

// The tangent columns of the blocks to eliminate by Schur complement (sorted) and of the rest:
// every variable block marked eliminated with tangent size 1, provided no residual block reads
// two of them (then their part of H is diagonal). Empty `eliminated` otherwise: dense solve.
void SchurPartition(const LeastSquaresProblem& problem, const NormalEquations& equations,
                    std::vector<int>* eliminated, std::vector<int>* kept) {
  eliminated->clear();
  kept->clear();
  const auto& blocks = problem.parameter_blocks();
  std::vector<char> is_eliminated(blocks.size(), 0);
  bool any = false;
  for (size_t i = 0; i < blocks.size(); ++i) {
    if (equations.TangentOffset(static_cast<int>(i)) < 0 || !blocks[i].eliminated) continue;
    if (blocks[i].TangentSize() != 1) return;
    is_eliminated[i] = 1;
    any = true;
  }
  if (!any) return;
  for (const LeastSquaresProblem::ResidualBlock& block : problem.residual_blocks()) {
    int count = 0;
    for (const int index : block.parameter_block_indices) count += is_eliminated[index];
    if (count > 1) return;
  }
  for (size_t i = 0; i < blocks.size(); ++i) {
    const int offset = equations.TangentOffset(static_cast<int>(i));
    if (offset < 0) continue;
    for (int c = 0; c < blocks[i].TangentSize(); ++c) {
      (is_eliminated[i] ? eliminated : kept)->push_back(offset + c);
    }
  }
  std::sort(eliminated->begin(), eliminated->end());
  std::sort(kept->begin(), kept->end());
}

// (H + lambda diag(H)) delta = -g with the eliminated columns P (diagonal H_PP) removed first:
//   S = H_KK - H_KP D^-1 H_PK,  S delta_K = -g_K + H_KP D^-1 g_P,
//   delta_P = D^-1 (-g_P - H_PK delta_K),
// D = (1 + lambda) diag(H_PP), K the kept columns (the same damping on S's diagonal). A column
// without information (D = 0, hence H_PK = 0 too) gets delta 0. Returns false when S is not
// factorisable.
bool SolveSchur(const Eigen::MatrixXd& hessian, const Eigen::VectorXd& gradient, double lambda,
                const std::vector<int>& eliminated, const std::vector<int>& kept,
                Eigen::LDLT<Eigen::MatrixXd>* ldlt, Eigen::VectorXd* delta) {
  const int num_eliminated = static_cast<int>(eliminated.size());
  Eigen::VectorXd d_inverse(num_eliminated);
  Eigen::VectorXd g_eliminated(num_eliminated);
  for (int i = 0; i < num_eliminated; ++i) {
    const double d = (1.0 + lambda) * hessian(eliminated[i], eliminated[i]);
    d_inverse[i] = d > 0.0 ? 1.0 / d : 0.0;
    g_eliminated[i] = gradient[eliminated[i]];
  }
  const Eigen::MatrixXd h_kp = hessian(kept, eliminated);
  const Eigen::VectorXd g_kept = gradient(kept);
  Eigen::VectorXd delta_kept = Eigen::VectorXd::Zero(static_cast<int>(kept.size()));
  if (!kept.empty()) {
    Eigen::MatrixXd schur = hessian(kept, kept);
    if (lambda > 0.0) schur.diagonal() *= 1.0 + lambda;
    schur.noalias() -= h_kp * d_inverse.asDiagonal() * h_kp.transpose();
    ldlt->compute(schur);
    if (ldlt->info() != Eigen::Success) return false;
    delta_kept = ldlt->solve(-g_kept + h_kp * d_inverse.cwiseProduct(g_eliminated));
  }
  const Eigen::VectorXd delta_eliminated =
      d_inverse.cwiseProduct(-g_eliminated - h_kp.transpose() * delta_kept);
  for (size_t i = 0; i < kept.size(); ++i) (*delta)[kept[i]] = delta_kept[i];
  for (int i = 0; i < num_eliminated; ++i) (*delta)[eliminated[i]] = delta_eliminated[i];
  return delta->allFinite();
}

}  // namespace

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
  // Blocks marked eliminated (LeastSquaresProblem::SetParameterBlockEliminated) are removed by
  // Schur complement when that is exact; otherwise the dense system is solved.
  std::vector<int> eliminated, kept;
  SchurPartition(*problem, *equations, &eliminated, &kept);
  Eigen::MatrixXd damped(eliminated.empty() ? n : 0, eliminated.empty() ? n : 0);
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
    bool step_ok = false;
    if (!eliminated.empty()) {
      step_ok = SolveSchur(equations->hessian(), equations->gradient(), lambda, eliminated, kept,
                           &ldlt, &delta);
    } else {
      damped = equations->hessian();
      if (lambda > 0.0) damped.diagonal() += lambda * equations->hessian().diagonal();
      ldlt.compute(damped);
      step_ok = ldlt.info() == Eigen::Success;
      if (step_ok) {
        delta = ldlt.solve(-equations->gradient());
        step_ok = delta.allFinite();
      }
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
