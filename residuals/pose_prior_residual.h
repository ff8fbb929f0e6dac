// A Gaussian prior on several poses, linearised at given poses T0_k: the residual whose squared
// norm / 2 is the quadratic energy a marginalisation leaves behind (DSO, Engel et al. PAMI 2018,
// Sec. 3.2; backend/windowed_ba/marginalization.h, windowed_ba_prior.h):
//
//   E(d) = 1/2 d^T H d + b^T d,   d = (d_1; ...; d_K),   d_k = Minus(T_k, T0_k) = Log(T_k T0_k^-1),
//   r    = S d + s,  with H = V L V^T, S = L^1/2 V^T, s = L^-1/2 V^T b over the eigenvalues
//          above 1e-12 of the largest (|r|^2 / 2 = E + const; a gauge direction of H is dropped).
//
// Parameter blocks: the K poses, double[7] each (SE3Manifold, cam_from_world). Tangent
// Jacobians: a left twist e on T_k moves d_k by InverseLeftJacobianSE3(d_k) e (exact), so
// dr/de_k = S_k J^-1(d_k), lifted to the 7 parameters through PoseMinusJacobian.
#ifndef PLDVO_RESIDUALS_POSE_PRIOR_RESIDUAL_H_
#define PLDVO_RESIDUALS_POSE_PRIOR_RESIDUAL_H_

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "core/se3.h"

namespace pldvo {

class PosePriorResidual : public ceres::CostFunction {
 public:
  // information: 6K x 6K symmetric positive semi-definite; gradient: 6K. Throws
  // std::invalid_argument on mismatched sizes, non-finite entries or an information without a
  // positive eigenvalue.
  PosePriorResidual(std::vector<SE3> linearization_poses, const Eigen::MatrixXd& information,
                    const Eigen::VectorXd& gradient);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::vector<SE3> linearization_poses_;
  Eigen::MatrixXd sqrt_information_;  // rows x 6K, S above
  Eigen::VectorXd offset_;            // s above
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_POSE_PRIOR_RESIDUAL_H_
