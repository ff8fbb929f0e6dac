// Photometric residual of one point of a host keyframe in a target keyframe of a window, for
// windowed bundle adjustment (docs/windowed_ba.md): the paper's r_i (eq. 2) with both poses, the
// point's inverse depth and both keyframes' affine brightness as variables, over a pattern of
// host pixels that share the point's inverse depth (DSO's residual pattern):
//
//   r_k = sqrt_info_k (e^{s} (I_h(x_k) - b_h) - e^{-s} (I_t(tau_k) - b_t)),   k = 1..N,
//   s = (a_t - a_h) / 2,   tau_k = pi(q_k),   q_k = R_th K^-1 (x_k; 1) + d t_th,
//   T_th = T_tw T_hw^-1   (T_hw = host cam_from_world, T_tw = target cam_from_world),
//
// with per-keyframe brightness I_k = e^{a_k} L + b_k of a radiance L, so that the transfer
// host -> target is I_t ~ e^{a_t - a_h} (I_h - b_h) + b_t, written in the symmetric form of
// residuals/photometric_residual.h (the two images treated alike). With a_h = a_t, b_h = b_t = 0
// it is I_h - I_t, the paper's r_i. q_k = d * point_in_target is valid at d = 0 (infinity).
//
// Parameter blocks: [0] host cam_from_world, [1] target cam_from_world (double[7] each,
// SE3Manifold), [2] the inverse depth d (double[1], host frame), [3] host brightness {a_h, b_h},
// [4] target brightness {a_t, b_t} (double[2], Euclidean). Tangent Jacobians (left twists,
// translation first), with c = dr/dq = -sqrt_info_k e^{-s} g^T dpi/dq (g the target image's
// gradient at tau_k), ray = K^-1 (x_k; 1):
//   dq/ddelta_t = [d I, -[q]x]                   (T_tw <- Exp(delta_t) T_tw)
//   dq/ddelta_h = [-d R_th, R_th [ray]x]         (T_hw <- Exp(delta_h) T_hw: T_th <- T_th
//   Exp(-delta_h)) dq/dd = t_th, dr/da_t = -dr/da_h = sqrt_info_k (e^{s} (I_h - b_h) + e^{-s} (I_t
//   - b_t)) / 2, dr/db_h = -sqrt_info_k e^{s},   dr/db_t = sqrt_info_k e^{-s},
// pose Jacobians lifted to 7 parameters through PoseMinusJacobian.
//
// Weighting: sqrt_info_k = 1 / sqrt(Sigma_f) from the photometric covariance model (eq. 5,
// residuals/weighting.h PhotometricSqrtInfo: 2 sigma_I^2 + (g^T J_d)^2 V with the point's inverse
// depth variance V), computed by the caller at the linearisation point, constant in a solve.
// Robust loss (optional, not owned): row-wise square-root form as in photometric_residual.h.
// Sampling of I_t: bilinear (ImagePyramid [I, Ix, Iy], the gradient is the interpolated central
// difference) or bicubic (exact derivative), as ImageInterpolation says. Validity: a row behind
// the target camera or outside [1, w - 2) x [1, h - 2) of the level has residual and Jacobian 0.
// Evaluate() does no heap allocation. The target pyramid must outlive this object.
#ifndef PLDVO_RESIDUALS_HOST_TARGET_PHOTOMETRIC_RESIDUAL_H_
#define PLDVO_RESIDUALS_HOST_TARGET_PHOTOMETRIC_RESIDUAL_H_

#include <ceres/cost_function.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "residuals/photometric_residual.h"

namespace pldvo {

// One host pixel of a point's pattern.
struct HostPixel {
  Eigen::Vector2d pixel_in_host = Eigen::Vector2d::Zero();  // at the residual's pyramid level
  double intensity_host = 0.0;                              // I_h(x), gray levels
  double sqrt_info = 1.0;                                   // 1 / sqrt(Sigma_f), >= 0
};

class HostTargetPhotometricResidual : public ceres::CostFunction {
 public:
  // `camera` is the camera of `level`. Throws std::invalid_argument on an empty pattern, a
  // level outside the pyramid, a camera whose size differs from the level's, or a non-finite
  // value / negative sqrt_info.
  HostTargetPhotometricResidual(const ImagePyramid& target_pyramid, int level,
                                const PinholeCamera& camera, std::vector<HostPixel> pattern,
                                const ceres::LossFunction* loss = nullptr,
                                ImageInterpolation interpolation = ImageInterpolation::kBilinear);

  static HostTargetPhotometricResidual* Create(
      const ImagePyramid& target_pyramid, int level, const PinholeCamera& camera,
      std::vector<HostPixel> pattern, const ceres::LossFunction* loss = nullptr,
      ImageInterpolation interpolation = ImageInterpolation::kBilinear) {
    return new HostTargetPhotometricResidual(target_pyramid, level, camera, std::move(pattern),
                                             loss, interpolation);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  int num_pixels() const { return static_cast<int>(pattern_.size()); }
  const std::vector<HostPixel>& pattern() const { return pattern_; }

 private:
  using IntensityGrid = ceres::Grid2D<float, 1>;
  using BicubicInterpolator = ceres::BiCubicInterpolator<IntensityGrid>;

  const ImagePyramid& target_pyramid_;
  const int level_;
  const PinholeCamera camera_;
  const std::vector<HostPixel> pattern_;
  std::vector<Eigen::Vector3d> rays_in_host_;  // K^-1 (x_k; 1)
  const ceres::LossFunction* loss_;
  const ImageInterpolation interpolation_;
  std::unique_ptr<const IntensityGrid> grid_;
  std::unique_ptr<const BicubicInterpolator> bicubic_;
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_HOST_TARGET_PHOTOMETRIC_RESIDUAL_H_
