// Scale gauge of monocular bundle adjustment: a prior that holds the distance between two camera
// centres at a given length b0 (docs/edge_ba.md, "Gauge"):
//
//   c_i = -R_i^T t_i                      (camera centre of cam_from_world_i in the world)
//   r   = (|c_b - c_a| - b0) / sigma_b.
//
// Parameter blocks: [0] cam_from_world_a, [1] cam_from_world_b, double[7] each (SE3Manifold).
// Tangent Jacobians (left twist (v; w) on cam_from_world): dc/dv = -R^T, dc/dw = 0, so with
// u = (c_b - c_a) / |c_b - c_a|:
//   dr/d(v_a, w_a) = [ u^T R_a^T, 0] / sigma_b,   dr/d(v_b, w_b) = [-u^T R_b^T, 0] / sigma_b,
// lifted to the 7 parameters through PoseMinusJacobian.
// Weighting: 1 / sigma_b. Because the image residuals are exactly invariant to a scaling of the
// world about the fixed first camera, the prior's residual is zero at the optimum for any
// sigma_b > 0: sigma_b only sets the conditioning, it does not trade off against the data.
// Validity: Evaluate returns false when the two centres coincide (|c_b - c_a| < 1e-12 m).
#ifndef PLDVO_RESIDUALS_BASELINE_PRIOR_RESIDUAL_H_
#define PLDVO_RESIDUALS_BASELINE_PRIOR_RESIDUAL_H_

#include <ceres/sized_cost_function.h>

namespace pldvo {

class BaselinePriorResidual : public ceres::SizedCostFunction<1, 7, 7> {
 public:
  // Throws std::invalid_argument unless baseline > 0 and sigma > 0 (finite).
  BaselinePriorResidual(double baseline, double sigma);

  static BaselinePriorResidual* Create(double baseline, double sigma) {
    return new BaselinePriorResidual(baseline, sigma);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const double baseline_;
  const double sigma_;
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_BASELINE_PRIOR_RESIDUAL_H_
