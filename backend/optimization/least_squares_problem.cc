#include "backend/optimization/least_squares_problem.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pldvo {

int LeastSquaresProblem::AddParameterBlock(double* values, int size,
                                           std::unique_ptr<ceres::Manifold> manifold) {
  if (values == nullptr || size <= 0) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": parameter block needs values and a positive size");
  }
  if (ParameterBlockIndex(values) >= 0) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": parameter block added twice");
  }
  if (manifold != nullptr && manifold->AmbientSize() != size) {
    throw std::invalid_argument(
        std::string(__FILE__) + ":" + std::to_string(__LINE__) + ": manifold ambient size " +
        std::to_string(manifold->AmbientSize()) + " != block size " + std::to_string(size));
  }
  ParameterBlock block;
  block.values = values;
  block.size = size;
  block.manifold = manifold.get();
  if (manifold != nullptr) owned_manifolds_.push_back(std::move(manifold));
  parameter_blocks_.push_back(block);
  return static_cast<int>(parameter_blocks_.size()) - 1;
}

int LeastSquaresProblem::ParameterBlockIndex(const double* values) const {
  for (size_t i = 0; i < parameter_blocks_.size(); ++i) {
    if (parameter_blocks_[i].values == values) return static_cast<int>(i);
  }
  return -1;
}

void LeastSquaresProblem::SetParameterBlockConstant(const double* values) {
  const int index = ParameterBlockIndex(values);
  if (index < 0) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": unknown parameter block");
  }
  parameter_blocks_[index].constant = true;
}

void LeastSquaresProblem::SetParameterBlockVariable(const double* values) {
  const int index = ParameterBlockIndex(values);
  if (index < 0) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": unknown parameter block");
  }
  parameter_blocks_[index].constant = false;
}

void LeastSquaresProblem::SetParameterBlockEliminated(const double* values) {
  const int index = ParameterBlockIndex(values);
  if (index < 0) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": unknown parameter block");
  }
  parameter_blocks_[index].eliminated = true;
}

std::vector<double*> LeastSquaresProblem::EliminatedBlocks() const {
  std::vector<double*> blocks;
  for (const ParameterBlock& block : parameter_blocks_) {
    if (block.eliminated) blocks.push_back(block.values);
  }
  return blocks;
}

ceres::LossFunction* LeastSquaresProblem::AddLossFunction(
    std::unique_ptr<ceres::LossFunction> loss_function) {
  owned_loss_functions_.push_back(std::move(loss_function));
  return owned_loss_functions_.back().get();
}

int LeastSquaresProblem::AddResidualBlock(std::unique_ptr<ceres::CostFunction> cost_function,
                                          ceres::LossFunction* loss_function,
                                          const std::vector<double*>& parameters) {
  if (cost_function == nullptr) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": null cost function");
  }
  const std::vector<int32_t>& sizes = cost_function->parameter_block_sizes();
  if (sizes.size() != parameters.size()) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": cost function expects " + std::to_string(sizes.size()) +
                                " parameter blocks, got " + std::to_string(parameters.size()));
  }
  ResidualBlock block;
  for (size_t i = 0; i < parameters.size(); ++i) {
    const int index = ParameterBlockIndex(parameters[i]);
    if (index < 0 || parameter_blocks_[index].size != sizes[i]) {
      throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                  ": parameter block " + std::to_string(i) +
                                  " not added or of the wrong size");
    }
    block.parameter_block_indices.push_back(index);
  }
  block.parameters = parameters;
  block.cost_function = cost_function.get();
  block.loss_function = loss_function;
  num_residuals_ += cost_function->num_residuals();
  max_block_residuals_ = std::max(max_block_residuals_, cost_function->num_residuals());
  owned_cost_functions_.push_back(std::move(cost_function));
  residual_blocks_.push_back(std::move(block));
  return static_cast<int>(residual_blocks_.size()) - 1;
}

bool LeastSquaresProblem::EvaluateCost(double* cost) const {
  std::vector<double> residuals(max_block_residuals_);
  double total = 0.0;
  for (const ResidualBlock& block : residual_blocks_) {
    const int n = block.cost_function->num_residuals();
    if (!block.cost_function->Evaluate(block.parameters.data(), residuals.data(), nullptr)) {
      return false;
    }
    double sq_norm = 0.0;
    for (int i = 0; i < n; ++i) sq_norm += residuals[i] * residuals[i];
    if (block.loss_function != nullptr) {
      double rho[3];
      block.loss_function->Evaluate(sq_norm, rho);
      total += 0.5 * rho[0];
    } else {
      total += 0.5 * sq_norm;
    }
  }
  *cost = total;
  return true;
}

std::unique_ptr<ceres::Problem> LeastSquaresProblem::ToCeresProblem() const {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  auto problem = std::make_unique<ceres::Problem>(options);
  for (const ParameterBlock& block : parameter_blocks_) {
    problem->AddParameterBlock(block.values, block.size, block.manifold);
    if (block.constant) problem->SetParameterBlockConstant(block.values);
  }
  for (const ResidualBlock& block : residual_blocks_) {
    problem->AddResidualBlock(block.cost_function, block.loss_function, block.parameters);
  }
  return problem;
}

}  // namespace pldvo
