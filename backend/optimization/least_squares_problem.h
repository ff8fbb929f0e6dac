// Our own description of a nonlinear least-squares problem
//
//   min_x  1/2 sum_k rho_k(|r_k(x_k)|^2),
//
// with parameter blocks (raw double arrays, an optional ceres::Manifold, a constant flag) and
// residual blocks (a ceres::CostFunction, an optional ceres::LossFunction rho_k, the parameter
// blocks it reads). Both solvers work on this one description: ToCeresProblem() hands the very
// same CostFunction/LossFunction/Manifold objects to ceres::Problem (which does not take
// ownership), and the hand-written Gauss-Newton (gauss_newton_solver.h) evaluates the same
// CostFunction::Evaluate and updates through the same Manifold::Plus. So when both converge
// they minimise the same objective by construction.
//
// Ownership: the problem owns every cost function and manifold added to it and the loss
// functions given to AddLossFunction; the parameter arrays belong to the caller and must outlive
// the problem.
#ifndef PLDVO_BACKEND_OPTIMIZATION_LEAST_SQUARES_PROBLEM_H_
#define PLDVO_BACKEND_OPTIMIZATION_LEAST_SQUARES_PROBLEM_H_

#include <ceres/ceres.h>

#include <memory>
#include <vector>

namespace pldvo {

class LeastSquaresProblem {
 public:
  struct ParameterBlock {
    double* values = nullptr;
    int size = 0;                         // ambient size
    ceres::Manifold* manifold = nullptr;  // nullptr: Euclidean
    bool constant = false;
    // Eliminated first in a Schur-complement solve (SetParameterBlockEliminated).
    bool eliminated = false;
    int TangentSize() const { return manifold != nullptr ? manifold->TangentSize() : size; }
  };
  struct ResidualBlock {
    ceres::CostFunction* cost_function = nullptr;
    ceres::LossFunction* loss_function = nullptr;  // nullptr: plain squares
    std::vector<int> parameter_block_indices;      // into parameter_blocks()
    std::vector<double*> parameters;               // the same blocks, as raw pointers
  };

  LeastSquaresProblem() = default;
  LeastSquaresProblem(const LeastSquaresProblem&) = delete;
  LeastSquaresProblem& operator=(const LeastSquaresProblem&) = delete;
  LeastSquaresProblem(LeastSquaresProblem&&) = default;
  LeastSquaresProblem& operator=(LeastSquaresProblem&&) = default;

  // Adds a parameter block; adding the same pointer twice throws std::invalid_argument. A
  // manifold must have AmbientSize() == size. Returns the block index.
  int AddParameterBlock(double* values, int size,
                        std::unique_ptr<ceres::Manifold> manifold = nullptr);
  void SetParameterBlockConstant(const double* values);
  void SetParameterBlockVariable(const double* values);
  // Marks a block to be eliminated first when the solver forms the Schur complement: a point's
  // inverse depth in bundle adjustment, whose normal-equation block is diagonal. The
  // Gauss-Newton solver eliminates marked blocks when each has tangent size 1 and no residual
  // block reads two of them (and solves densely otherwise); a Ceres Schur ordering can be
  // made from EliminatedBlocks(). It changes the linear algebra, never the objective.
  void SetParameterBlockEliminated(const double* values);
  // The parameter arrays of the blocks marked eliminated, in the order they were added.
  std::vector<double*> EliminatedBlocks() const;

  // Takes ownership of a loss function and returns it, so that residual blocks (or cost
  // functions that robustify row-wise inside) can share it for the problem's lifetime.
  ceres::LossFunction* AddLossFunction(std::unique_ptr<ceres::LossFunction> loss_function);

  // Adds a residual block over parameter blocks that must already have been added, in the
  // order and with the sizes the cost function declares (otherwise std::invalid_argument).
  // `loss_function` is not owned by this call: nullptr, one returned by AddLossFunction, or one
  // that outlives the problem. Returns the residual block index.
  int AddResidualBlock(std::unique_ptr<ceres::CostFunction> cost_function,
                       ceres::LossFunction* loss_function, const std::vector<double*>& parameters);

  const std::vector<ParameterBlock>& parameter_blocks() const { return parameter_blocks_; }
  const std::vector<ResidualBlock>& residual_blocks() const { return residual_blocks_; }
  // Index of a parameter block, -1 when it was not added.
  int ParameterBlockIndex(const double* values) const;
  // Total number of scalar residuals over all residual blocks.
  int NumResiduals() const { return num_residuals_; }
  // The largest residual count of one block (to size evaluation buffers once).
  int MaxBlockResiduals() const { return max_block_residuals_; }

  // 1/2 sum_k rho_k(|r_k|^2) at the current parameter values, the objective Ceres reports.
  // Returns false when a cost function fails to evaluate.
  bool EvaluateCost(double* cost) const;

  // A ceres::Problem over the same parameter arrays and the same (non-owned) cost functions,
  // loss functions and manifolds. It must not outlive this object.
  std::unique_ptr<ceres::Problem> ToCeresProblem() const;

 private:
  std::vector<ParameterBlock> parameter_blocks_;
  std::vector<ResidualBlock> residual_blocks_;
  std::vector<std::unique_ptr<ceres::Manifold>> owned_manifolds_;
  std::vector<std::unique_ptr<ceres::CostFunction>> owned_cost_functions_;
  std::vector<std::unique_ptr<ceres::LossFunction>> owned_loss_functions_;
  int num_residuals_ = 0;
  int max_block_residuals_ = 0;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_LEAST_SQUARES_PROBLEM_H_
