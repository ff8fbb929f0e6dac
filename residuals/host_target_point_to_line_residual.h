// Point-to-line residual of one edge point of a host keyframe against the line matched to its
// edge in a target keyframe of a window, for windowed bundle adjustment (docs/windowed_ba.md):
// the paper's g_j (eq. 3) with both poses and the point's inverse depth as variables,
//
//   g = sqrt_info * l^T (tau; 1),   tau = pi(q),   q = R_th K^-1 (x; 1) + d t_th,
//   T_th = T_tw T_hw^-1,
//
// with l = (a, b, c), a^2 + b^2 = 1, the target line in the level's pixels (signed distance).
//
// Parameter blocks: [0] host cam_from_world, [1] target cam_from_world (double[7], SE3Manifold),
// [2] the inverse depth d (double[1]). Tangent Jacobians with c = sqrt_info (a, b) dpi/dq:
//   dg/ddelta_t = [d c, (q x c)^T],  dg/ddelta_h = [-d (R_th^T c)^T, ((R_th^T c) x ray)^T],
//   dg/dd = c^T t_th
// (host_target_photometric_residual.h has the derivation), lifted through PoseMinusJacobian.
//
// Weighting: sqrt_info = 1 / sqrt(Sigma_g) from PointToLineVariance (eq. 6, residuals/weighting.h
// LineSqrtInfo: the reprojected pixel's covariance from the inverse depth variance plus the
// line's), computed by the caller at the linearisation point and constant inside a solve.
// Robust loss (optional, not owned): square-root form (residuals/robustify.h); or pass it to
// the problem instead (one row per block), not both. Validity: behind the target camera or
// outside [0, w - 1] x [0, h - 1] -> residual and Jacobian 0 (point_to_line_residual.h's rule).
#ifndef PLDVO_RESIDUALS_HOST_TARGET_POINT_TO_LINE_RESIDUAL_H_
#define PLDVO_RESIDUALS_HOST_TARGET_POINT_TO_LINE_RESIDUAL_H_

#include <ceres/loss_function.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "core/pinhole_camera.h"

namespace pldvo {

class HostTargetPointToLineResidual : public ceres::SizedCostFunction<1, 7, 7, 1> {
 public:
  // Throws std::invalid_argument on an invalid camera, a non-finite pixel, |a^2 + b^2 - 1| >
  // 1e-6 or a negative / non-finite sqrt_info.
  HostTargetPointToLineResidual(const PinholeCamera& camera, const Eigen::Vector2d& pixel_in_host,
                                const Eigen::Vector3d& line_in_target, double sqrt_info,
                                const ceres::LossFunction* loss = nullptr);

  static HostTargetPointToLineResidual* Create(const PinholeCamera& camera,
                                               const Eigen::Vector2d& pixel_in_host,
                                               const Eigen::Vector3d& line_in_target,
                                               double sqrt_info,
                                               const ceres::LossFunction* loss = nullptr) {
    return new HostTargetPointToLineResidual(camera, pixel_in_host, line_in_target, sqrt_info,
                                             loss);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  double sqrt_info() const { return sqrt_info_; }

 private:
  const PinholeCamera camera_;
  const Eigen::Vector3d ray_in_host_;
  const Eigen::Vector3d line_in_target_;
  const double sqrt_info_;
  const ceres::LossFunction* loss_;
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_HOST_TARGET_POINT_TO_LINE_RESIDUAL_H_
