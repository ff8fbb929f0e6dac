#include "backend/gauss_newton_solver.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace pldvo {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Per-solve bookkeeping for the variable parameter blocks and the evaluation buffers, all sized
// once so that linearisation does not allocate per residual block.
class NormalEquations {
 public:
  explicit NormalEquations(const LeastSquaresProblem& problem) : problem_(problem) {
    const auto& blocks = problem.parameter_blocks();
    tangent_offset_.assign(blocks.size(), -1);
    plus_jacobian_.resize(blocks.size());
    ambient_jacobian_.resize(blocks.size());
    tangent_jacobian_.resize(blocks.size());
    const int max_rows = problem.MaxBlockResiduals();
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (blocks[i].constant) continue;
      tangent_offset_[i] = dimension_;
      dimension_ += blocks[i].TangentSize();
      plus_jacobian_[i].resize(blocks[i].size * blocks[i].TangentSize());
      ambient_jacobian_[i].resize(static_cast<size_t>(max_rows) * blocks[i].size);
      tangent_jacobian_[i].resize(static_cast<size_t>(max_rows) * blocks[i].TangentSize());
    }
    residuals_.resize(max_rows);
    row_.resize(dimension_);
    jacobian_pointers_.resize(blocks.size());
    hessian_.resize(dimension_, dimension_);
    gradient_.resize(dimension_);
  }

  int dimension() const { return dimension_; }
  const Eigen::MatrixXd& hessian() const { return hessian_; }
  const Eigen::VectorXd& gradient() const { return gradient_; }

  // Evaluates cost, H = J~^T J~ and g = J~^T r~ at the current parameters.
  bool Linearize(double* cost) {
    const auto& blocks = problem_.parameter_blocks();
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (tangent_offset_[i] < 0) continue;
      if (blocks[i].manifold == nullptr) {
        Eigen::Map<RowMajorMatrix>(plus_jacobian_[i].data(), blocks[i].size, blocks[i].size)
            .setIdentity();
      } else if (!blocks[i].manifold->PlusJacobian(blocks[i].values, plus_jacobian_[i].data())) {
        return false;
      }
    }
    hessian_.setZero();
    gradient_.setZero();
    double total_cost = 0.0;
    for (const LeastSquaresProblem::ResidualBlock& block : problem_.residual_blocks()) {
      const int rows = block.cost_function->num_residuals();
      const int num_blocks = static_cast<int>(block.parameter_block_indices.size());
      for (int k = 0; k < num_blocks; ++k) {
        const int index = block.parameter_block_indices[k];
        jacobian_pointers_[k] =
            tangent_offset_[index] >= 0 ? ambient_jacobian_[index].data() : nullptr;
      }
      if (!block.cost_function->Evaluate(block.parameters.data(), residuals_.data(),
                                         jacobian_pointers_.data())) {
        return false;
      }
      double sq_norm = 0.0;
      for (int r = 0; r < rows; ++r) sq_norm += residuals_[r] * residuals_[r];

      // Robust correction of a LossFunction (Ceres' Corrector, see the header).
      double residual_scaling = 1.0;
      double jacobian_scaling = 1.0;
      double alpha_sq_norm = 0.0;
      if (block.loss_function != nullptr) {
        double rho[3];
        block.loss_function->Evaluate(sq_norm, rho);
        total_cost += 0.5 * rho[0];
        if (rho[1] <= 0.0) continue;  // a fully down-weighted block adds nothing
        const double sqrt_rho1 = std::sqrt(rho[1]);
        jacobian_scaling = sqrt_rho1;
        residual_scaling = sqrt_rho1;
        if (sq_norm > 0.0 && rho[2] > 0.0) {
          const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
          residual_scaling = sqrt_rho1 / (1.0 - alpha);
          alpha_sq_norm = alpha / sq_norm;
        }
      } else {
        total_cost += 0.5 * sq_norm;
      }

      // Tangent-space Jacobians: J_tangent = J_ambient * PlusJacobian.
      int variable_blocks = 0;
      int last_variable = -1;
      for (int k = 0; k < num_blocks; ++k) {
        const int index = block.parameter_block_indices[k];
        if (tangent_offset_[index] < 0) continue;
        ++variable_blocks;
        last_variable = index;
        const int ambient = problem_.parameter_blocks()[index].size;
        const int tangent = problem_.parameter_blocks()[index].TangentSize();
        Eigen::Map<const RowMajorMatrix> plus(plus_jacobian_[index].data(), ambient, tangent);
        Eigen::Map<const RowMajorMatrix> jac_ambient(ambient_jacobian_[index].data(), rows,
                                                     ambient);
        Eigen::Map<RowMajorMatrix> jac_tangent(tangent_jacobian_[index].data(), rows, tangent);
        jac_tangent.noalias() = jac_ambient * plus;
        if (alpha_sq_norm != 0.0) {
          // J <- J - alpha/s r (r^T J).
          Eigen::Map<const Eigen::VectorXd> r(residuals_.data(), rows);
          const Eigen::RowVectorXd r_dot_j = r.transpose() * jac_tangent;
          jac_tangent.noalias() -= (alpha_sq_norm * r) * r_dot_j;
        }
      }

      if (variable_blocks == 1) {
        // One variable block (the tracking problems): H_bb += s^2 J^T J, g_b += s J^T (rs r) as
        // block products.
        const int offset = tangent_offset_[last_variable];
        const int tangent = problem_.parameter_blocks()[last_variable].TangentSize();
        Eigen::Map<const RowMajorMatrix> jac(tangent_jacobian_[last_variable].data(), rows,
                                             tangent);
        Eigen::Map<const Eigen::VectorXd> r(residuals_.data(), rows);
        hessian_.block(offset, offset, tangent, tangent)
            .selfadjointView<Eigen::Upper>()
            .rankUpdate(jac.transpose(), jacobian_scaling * jacobian_scaling);
        gradient_.segment(offset, tangent).noalias() +=
            (jacobian_scaling * residual_scaling) * (jac.transpose() * r);
        continue;
      }

      // Accumulate the upper triangle of H and g row by row through a dense tangent row.
      for (int r = 0; r < rows; ++r) {
        std::fill(row_.begin(), row_.end(), 0.0);
        for (int k = 0; k < num_blocks; ++k) {
          const int index = block.parameter_block_indices[k];
          const int offset = tangent_offset_[index];
          if (offset < 0) continue;
          const int tangent = problem_.parameter_blocks()[index].TangentSize();
          const double* jac_row = tangent_jacobian_[index].data() + r * tangent;
          for (int c = 0; c < tangent; ++c) row_[offset + c] += jacobian_scaling * jac_row[c];
        }
        const double residual = residual_scaling * residuals_[r];
        for (int a = 0; a < dimension_; ++a) {
          const double ja = row_[a];
          if (ja == 0.0) continue;
          gradient_[a] += ja * residual;
          for (int b = a; b < dimension_; ++b) hessian_(a, b) += ja * row_[b];
        }
      }
    }
    hessian_.triangularView<Eigen::StrictlyLower>() = hessian_.transpose();
    *cost = total_cost;
    return true;
  }

  // x <- Plus(x, delta) for every variable block, keeping the previous values in `backup`.
  bool ApplyStep(const Eigen::VectorXd& delta, std::vector<double>* backup) {
    backup->clear();
    const auto& blocks = problem_.parameter_blocks();
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (tangent_offset_[i] < 0) continue;
      backup->insert(backup->end(), blocks[i].values, blocks[i].values + blocks[i].size);
      const double* step = delta.data() + tangent_offset_[i];
      if (blocks[i].manifold == nullptr) {
        for (int j = 0; j < blocks[i].size; ++j) blocks[i].values[j] += step[j];
      } else {
        std::vector<double>& scratch = ambient_scratch_;
        scratch.assign(blocks[i].size, 0.0);
        if (!blocks[i].manifold->Plus(blocks[i].values, step, scratch.data())) return false;
        std::copy(scratch.begin(), scratch.end(), blocks[i].values);
      }
    }
    return true;
  }

  void Restore(const std::vector<double>& backup) {
    size_t position = 0;
    for (size_t i = 0; i < problem_.parameter_blocks().size(); ++i) {
      const auto& block = problem_.parameter_blocks()[i];
      if (tangent_offset_[i] < 0) continue;
      std::copy(backup.begin() + position, backup.begin() + position + block.size, block.values);
      position += block.size;
    }
  }

  double ParameterNorm() const {
    double sq = 0.0;
    const auto& blocks = problem_.parameter_blocks();
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (tangent_offset_[i] < 0) continue;
      for (int j = 0; j < blocks[i].size; ++j) sq += blocks[i].values[j] * blocks[i].values[j];
    }
    return std::sqrt(sq);
  }

 private:
  const LeastSquaresProblem& problem_;
  int dimension_ = 0;
  std::vector<int> tangent_offset_;                 // per parameter block, -1 if constant
  std::vector<std::vector<double>> plus_jacobian_;  // ambient x tangent, row-major
  std::vector<std::vector<double>> ambient_jacobian_;
  std::vector<std::vector<double>> tangent_jacobian_;
  std::vector<double> residuals_;
  std::vector<double> row_;
  std::vector<double> ambient_scratch_;
  std::vector<double*> jacobian_pointers_;
  Eigen::MatrixXd hessian_;
  Eigen::VectorXd gradient_;
};

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
