// A cost function whose first parameter block is a pose on SE3Manifold and that can give its
// Jacobian in the pose's 6-D tangent directly (residuals/se3_manifold.h).
//
// Such a cost function computes J_tangent first and lifts it to the 7 ambient parameters for
// Ceres; the Gauss-Newton normal equations need J_ambient * PlusJacobian(x) = J_tangent again.
// NormalEquations takes the tangent rows directly when the pose is the block's only variable
// parameter block: the same H and g up to rounding, without the lift and the product back
// (docs/tracking.md, "Problem description and the two solvers").
#ifndef PLDVO_RESIDUALS_POSE_TANGENT_COST_FUNCTION_H_
#define PLDVO_RESIDUALS_POSE_TANGENT_COST_FUNCTION_H_

namespace pldvo {

class PoseTangentCostFunction {
 public:
  virtual ~PoseTangentCostFunction() = default;

  // The residuals Evaluate() gives at `parameters` and their Jacobian with respect to the
  // tangent of parameters[0] (num_residuals x 6, row-major); the other blocks are held fixed.
  virtual bool EvaluatePoseTangent(double const* const* parameters, double* residuals,
                                   double* jacobian_tangent) const = 0;
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_POSE_TANGENT_COST_FUNCTION_H_
