#include "backend/optimization/normal_equations.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "residuals/pose_tangent_cost_function.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace

NormalEquations::NormalEquations(const LeastSquaresProblem& problem) : problem_(problem) {
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
  // Blocks whose only variable parameter block is their first, an SE3Manifold pose, and whose
  // cost function gives the tangent Jacobian directly.
  const auto& residual_blocks = problem.residual_blocks();
  pose_tangent_.assign(residual_blocks.size(), nullptr);
  for (size_t b = 0; b < residual_blocks.size(); ++b) {
    const std::vector<int>& indices = residual_blocks[b].parameter_block_indices;
    const auto* cost =
        dynamic_cast<const PoseTangentCostFunction*>(residual_blocks[b].cost_function);
    if (cost == nullptr || indices.empty() || tangent_offset_[indices[0]] < 0 ||
        dynamic_cast<const SE3Manifold*>(blocks[indices[0]].manifold) == nullptr) {
      continue;
    }
    const bool others_constant = std::all_of(indices.begin() + 1, indices.end(),
                                             [&](int index) { return tangent_offset_[index] < 0; });
    if (others_constant) pose_tangent_[b] = cost;
  }
  residuals_.resize(max_rows);
  row_.resize(dimension_);
  columns_.reserve(dimension_);
  jacobian_pointers_.resize(blocks.size());
  hessian_.resize(dimension_, dimension_);
  gradient_.resize(dimension_);
}

bool NormalEquations::Linearize(double* cost) { return LinearizeBlocks(nullptr, cost); }

bool NormalEquations::LinearizeBlocks(const std::vector<int>* residual_blocks, double* cost) {
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
  if (residual_blocks == nullptr) {
    for (size_t b = 0; b < problem_.residual_blocks().size(); ++b) {
      if (!AddResidualBlock(static_cast<int>(b), &total_cost)) return false;
    }
  } else {
    for (const int b : *residual_blocks) {
      if (!AddResidualBlock(b, &total_cost)) return false;
    }
  }
  hessian_.triangularView<Eigen::StrictlyLower>() = hessian_.transpose();
  *cost = total_cost;
  return true;
}

bool NormalEquations::AddResidualBlock(int b, double* total_cost) {
  const LeastSquaresProblem::ResidualBlock& block = problem_.residual_blocks()[b];
  const int rows = block.cost_function->num_residuals();
  const int num_blocks = static_cast<int>(block.parameter_block_indices.size());
  const PoseTangentCostFunction* pose_tangent = pose_tangent_[b];
  if (pose_tangent != nullptr) {
    double* jacobian = tangent_jacobian_[block.parameter_block_indices[0]].data();
    if (!pose_tangent->EvaluatePoseTangent(block.parameters.data(), residuals_.data(), jacobian)) {
      return false;
    }
  } else {
    for (int k = 0; k < num_blocks; ++k) {
      const int index = block.parameter_block_indices[k];
      jacobian_pointers_[k] =
          tangent_offset_[index] >= 0 ? ambient_jacobian_[index].data() : nullptr;
    }
    if (!block.cost_function->Evaluate(block.parameters.data(), residuals_.data(),
                                       jacobian_pointers_.data())) {
      return false;
    }
  }
  double sq_norm = 0.0;
  for (int r = 0; r < rows; ++r) sq_norm += residuals_[r] * residuals_[r];

  // Robust correction of a LossFunction (Ceres' Corrector; equations: gauss_newton_solver.h).
  double residual_scaling = 1.0;
  double jacobian_scaling = 1.0;
  double alpha_sq_norm = 0.0;
  if (block.loss_function != nullptr) {
    double rho[3];
    block.loss_function->Evaluate(sq_norm, rho);
    *total_cost += 0.5 * rho[0];
    if (rho[1] <= 0.0) return true;  // a fully down-weighted block adds nothing
    const double sqrt_rho1 = std::sqrt(rho[1]);
    jacobian_scaling = sqrt_rho1;
    residual_scaling = sqrt_rho1;
    if (sq_norm > 0.0 && rho[2] > 0.0) {
      const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
      residual_scaling = sqrt_rho1 / (1.0 - alpha);
      alpha_sq_norm = alpha / sq_norm;
    }
  } else {
    *total_cost += 0.5 * sq_norm;
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
    Eigen::Map<RowMajorMatrix> jac_tangent(tangent_jacobian_[index].data(), rows, tangent);
    if (pose_tangent == nullptr) {
      Eigen::Map<const RowMajorMatrix> plus(plus_jacobian_[index].data(), ambient, tangent);
      Eigen::Map<const RowMajorMatrix> jac_ambient(ambient_jacobian_[index].data(), rows, ambient);
      jac_tangent.noalias() = jac_ambient * plus;
    }
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
    Eigen::Map<const RowMajorMatrix> jac(tangent_jacobian_[last_variable].data(), rows, tangent);
    Eigen::Map<const Eigen::VectorXd> r(residuals_.data(), rows);
    hessian_.block(offset, offset, tangent, tangent)
        .selfadjointView<Eigen::Upper>()
        .rankUpdate(jac.transpose(), jacobian_scaling * jacobian_scaling);
    gradient_.segment(offset, tangent).noalias() +=
        (jacobian_scaling * residual_scaling) * (jac.transpose() * r);
    return true;
  }

  // Accumulate the upper triangle of H and g row by row through a dense tangent row, visiting
  // only the columns of this block's variable parameter blocks (sorted, so that every entry
  // receives the same sums in the same order as a sweep over all columns would give it).
  columns_.clear();
  for (int k = 0; k < num_blocks; ++k) {
    const int index = block.parameter_block_indices[k];
    const int offset = tangent_offset_[index];
    if (offset < 0) continue;
    const int tangent = problem_.parameter_blocks()[index].TangentSize();
    for (int c = 0; c < tangent; ++c) columns_.push_back(offset + c);
  }
  std::sort(columns_.begin(), columns_.end());
  const int num_columns = static_cast<int>(columns_.size());
  for (int r = 0; r < rows; ++r) {
    for (const int column : columns_) row_[column] = 0.0;
    for (int k = 0; k < num_blocks; ++k) {
      const int index = block.parameter_block_indices[k];
      const int offset = tangent_offset_[index];
      if (offset < 0) continue;
      const int tangent = problem_.parameter_blocks()[index].TangentSize();
      const double* jac_row = tangent_jacobian_[index].data() + r * tangent;
      for (int c = 0; c < tangent; ++c) row_[offset + c] += jacobian_scaling * jac_row[c];
    }
    const double residual = residual_scaling * residuals_[r];
    for (int i = 0; i < num_columns; ++i) {
      const int a = columns_[i];
      const double ja = row_[a];
      if (ja == 0.0) continue;
      gradient_[a] += ja * residual;
      for (int j = i; j < num_columns; ++j) hessian_(a, columns_[j]) += ja * row_[columns_[j]];
    }
  }
  return true;
}

bool NormalEquations::ApplyStep(const Eigen::VectorXd& delta, std::vector<double>* backup) {
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

void NormalEquations::Restore(const std::vector<double>& backup) {
  size_t position = 0;
  for (size_t i = 0; i < problem_.parameter_blocks().size(); ++i) {
    const auto& block = problem_.parameter_blocks()[i];
    if (tangent_offset_[i] < 0) continue;
    std::copy(backup.begin() + position, backup.begin() + position + block.size, block.values);
    position += block.size;
  }
}

double NormalEquations::ParameterNorm() const {
  double sq = 0.0;
  const auto& blocks = problem_.parameter_blocks();
  for (size_t i = 0; i < blocks.size(); ++i) {
    if (tangent_offset_[i] < 0) continue;
    for (int j = 0; j < blocks[i].size; ++j) sq += blocks[i].values[j] * blocks[i].values[j];
  }
  return std::sqrt(sq);
}

}  // namespace pldvo
