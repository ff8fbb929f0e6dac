// Point-to-line residual of a batch of reference edge pixels against matched current-frame
// lines (Yang & Scherer, ICRA 2017, Sec. IV: the geometric term g_j of eq. 3 and its variance
// Sigma_g of eq. 6; see docs/residuals.md):
//
//   g_j = sqrt_info_j * l_j^T (tau(x_j, d_j, xi); 1),   j = 1..N,
//
// with l_j = (a, b, c), a^2 + b^2 = 1, so l_j^T (u, v, 1) is the signed pixel distance of the
// reprojected edge pixel to the line (covariance_models.h FitLine), and
// tau(x, d, xi) = pi(R K^-1 (x; 1) + d t) as in photometric_residual.h.
//
// Parameter block: one pose, double[7] = cur_from_ref (SE3Manifold). Tangent Jacobian
//   dg_j/dxi = sqrt_info_j (a, b) dpi/dp [I, -[p']x],
// lifted to the 7 parameters by J_tangent * MinusJacobian(x).
//
// Weighting: sqrt_info_j = 1 / sqrt(Sigma_g) from PointToLineVariance (weighting.h), computed
// by the caller at the linearisation point and held constant inside a solve.
// Shared line error (optional, one block = one edge; weighting.h SharedLineErrorWeights): the
// rows e_j = sqrt_info_j l^T x'_j (sqrt_info_j = (l^T Sigma_x'j l)^-1/2, the point part) are
// whitened against the line error all of them share, Cov(g) = D + X Sigma_l X^T:
//   r = (I + V V^T)^-1/2 e = e - V M V^T e,
// with V (N x 2) and M (2 x 2) fixed at the linearisation point; the Jacobian rows are mixed
// alike. Rows invalid at the evaluated pose enter the mix as 0 and come out as 0.
// Robust loss (optional, not owned): row-wise square-root form, exactly as in
// photometric_residual.h (residuals/robustify.h).
// Validity: behind the camera (z <= 0) or outside the level's image [0, w - 1] x [0, h - 1]
// -> residual 0, Jacobian row 0, valid(i) false; same rules as PhotometricResidual.
// Evaluate() does no heap allocation (its N x 6 tangent buffer is allocated once).
#ifndef PLDVO_RESIDUALS_POINT_TO_LINE_RESIDUAL_H_
#define PLDVO_RESIDUALS_POINT_TO_LINE_RESIDUAL_H_

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/pose_tangent_cost_function.h"

namespace pldvo {

// (I + V V^T)^-1/2 = I - V M V^T of a shared line error; empty v: independent rows.
struct SharedLineError {
  Eigen::Matrix<double, Eigen::Dynamic, 2> v;  // D^-1/2 X B, N x 2
  Eigen::Matrix2d m = Eigen::Matrix2d::Zero();
};

// One reference edge pixel with its matched current-frame line.
struct PointToLineObservation {
  Eigen::Vector2d pixel_in_ref = Eigen::Vector2d::Zero();  // at the residual's pyramid level
  double idepth = 0.0;                                     // inverse depth in ref, >= 0
  Eigen::Vector3d line_in_cur = Eigen::Vector3d::Zero();   // a^2 + b^2 = 1, same level's pixels
  double sqrt_info = 1.0;                                  // 1 / sqrt(Sigma_g) in 1/px, >= 0
};

class PointToLineResidual : public ceres::CostFunction, public PoseTangentCostFunction {
 public:
  // `camera` is the camera of the level the pixels and lines are expressed in. Throws
  // std::invalid_argument on an empty batch, an invalid camera, |a^2 + b^2 - 1| > 1e-6, a
  // non-finite / negative idepth or sqrt_info, or a non-empty `shared` whose v does not have
  // one row per observation.
  PointToLineResidual(const PinholeCamera& camera, std::vector<PointToLineObservation> observations,
                      const ceres::LossFunction* loss = nullptr, SharedLineError shared = {});

  static PointToLineResidual* Create(const PinholeCamera& camera,
                                     std::vector<PointToLineObservation> observations,
                                     const ceres::LossFunction* loss = nullptr,
                                     SharedLineError shared = {}) {
    return new PointToLineResidual(camera, std::move(observations), loss, std::move(shared));
  }

  // parameters[0] = cur_from_ref (7). jacobians[0], if requested, is N x 7 row-major.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // The rows of Evaluate() with the pose Jacobian in the tangent space (N x 6 row-major).
  bool EvaluatePoseTangent(double const* const* parameters, double* residuals,
                           double* jacobian_tangent) const override;

  // Tangent-space evaluation (N x 6 row-major Jacobian, may be nullptr; `valid` may be nullptr).
  void EvaluateTangent(const SE3& cur_from_ref, double* residuals, double* jacobian_tangent,
                       std::uint8_t* valid) const;

  // The reprojected edge pixels for a pose, with their validity; NaN behind the camera.
  // Allocates.
  std::vector<Eigen::Vector2d> ReprojectedPixels(const SE3& cur_from_ref,
                                                 std::vector<std::uint8_t>* valid = nullptr) const;

  int num_observations() const { return static_cast<int>(observations_.size()); }
  const std::vector<PointToLineObservation>& observations() const { return observations_; }
  bool valid(int i) const { return valid_[i] != 0; }
  int num_valid() const;

 private:
  const PinholeCamera camera_;
  const std::vector<PointToLineObservation> observations_;
  std::vector<Eigen::Vector3d> rays_in_ref_;
  const ceres::LossFunction* loss_;
  const SharedLineError shared_;
  mutable std::vector<std::uint8_t> valid_;
  mutable std::vector<double> tangent_;  // N x 6 tangent Jacobian (Evaluate's buffer)
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_POINT_TO_LINE_RESIDUAL_H_
