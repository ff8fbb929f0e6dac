// The normal equations H = J~^T J~, g = J~^T r~ of a LeastSquaresProblem at its current
// parameters, over the tangent spaces of its variable blocks (J~, r~: the whitened rows with
// Ceres' robust correction of a block's LossFunction; gauss_newton_solver.h has the equations).
// The Gauss-Newton solver steps with them; the tracker inverts H at its solution for the pose
// covariance. Buffers are sized once per problem, so linearising does not allocate per block.
#ifndef PLDVO_BACKEND_OPTIMIZATION_NORMAL_EQUATIONS_H_
#define PLDVO_BACKEND_OPTIMIZATION_NORMAL_EQUATIONS_H_

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "backend/optimization/least_squares_problem.h"
#include "residuals/pose_tangent_cost_function.h"

namespace pldvo {

class NormalEquations {
 public:
  explicit NormalEquations(const LeastSquaresProblem& problem);

  // Total tangent dimension of the variable blocks.
  int dimension() const { return dimension_; }
  // Offset of parameter block `index` in the tangent vector; -1 for a constant block.
  int TangentOffset(int index) const { return tangent_offset_[index]; }
  const Eigen::MatrixXd& hessian() const { return hessian_; }
  // Residual blocks whose rows come in the pose tangent directly (PoseTangentCostFunction).
  int num_pose_tangent_blocks() const {
    return static_cast<int>(pose_tangent_.size()) -
           static_cast<int>(std::count(pose_tangent_.begin(), pose_tangent_.end(), nullptr));
  }
  const Eigen::VectorXd& gradient() const { return gradient_; }

  // Evaluates cost, H and g at the current parameters; false when an evaluation fails.
  bool Linearize(double* cost);
  // The same over the given residual blocks only (indices into the problem's residual_blocks();
  // nullptr: all), e.g. the rows a marginalisation removes.
  bool LinearizeBlocks(const std::vector<int>* residual_blocks, double* cost);
  // x <- Plus(x, delta) for every variable block, keeping the previous values in `backup`.
  bool ApplyStep(const Eigen::VectorXd& delta, std::vector<double>* backup);
  void Restore(const std::vector<double>& backup);
  double ParameterNorm() const;

 private:
  // Adds residual block `b`'s cost to *total_cost and its rows to H and g.
  bool AddResidualBlock(int b, double* total_cost);

  const LeastSquaresProblem& problem_;
  int dimension_ = 0;
  std::vector<int> tangent_offset_;                 // per parameter block, -1 if constant
  std::vector<std::vector<double>> plus_jacobian_;  // ambient x tangent, row-major
  std::vector<std::vector<double>> ambient_jacobian_;
  std::vector<std::vector<double>> tangent_jacobian_;
  // Per residual block: its cost function when it gives the pose's tangent Jacobian directly
  // (PoseTangentCostFunction) and the pose is its only variable block; nullptr otherwise.
  std::vector<const PoseTangentCostFunction*> pose_tangent_;
  std::vector<double> residuals_;
  std::vector<double> row_;
  std::vector<int> columns_;  // tangent columns of one residual block's variable blocks, sorted
  std::vector<double> ambient_scratch_;
  std::vector<double*> jacobian_pointers_;
  Eigen::MatrixXd hessian_;
  Eigen::VectorXd gradient_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_NORMAL_EQUATIONS_H_
