// Observation models that turn measurement noise into residual covariances (first-order error
// propagation). All models of pldvo live here; residuals/weighting.h turns them into sqrt_info.
// Derivations: docs/residuals.md. Each model is checked against Monte Carlo sampling of the
// real nonlinear function in tests/residuals/covariance_models_test.cc.
//
// Notation (Yang & Scherer, ICRA 2017, Sec. IV): x a reference pixel, d its inverse depth with
// variance V, tau(x, d, xi) = pi(T(xi) pi^-1(x, d)) the reprojection into the current frame,
// l = (a, b, c) a current-frame line with a^2 + b^2 = 1 so that l^T (u, v, 1) is the signed
// distance in pixels.
#ifndef PLDVO_RESIDUALS_COVARIANCE_MODELS_H_
#define PLDVO_RESIDUALS_COVARIANCE_MODELS_H_

#include <Eigen/Core>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// ---------------------------------------------------------------------------------------------
// Reprojection and its inverse-depth derivative.

// tau(x, d): the reference pixel `pixel_in_ref` with inverse depth `idepth` (>= 0; 0 is a point
// at infinity) seen in the current camera. Computed as pi(R K^-1 (u, v, 1) + d t), which equals
// pi(cur_from_ref * pi^-1(x, d)) for d > 0. Returns false when the point lies on or behind the
// current camera's image plane (z <= 0); `pixel_in_cur` is then unspecified.
bool Reproject(const PinholeCamera& camera, const SE3& cur_from_ref,
               const Eigen::Vector2d& pixel_in_ref, double idepth, Eigen::Vector2d* pixel_in_cur);

// J_d = d tau / d d (2x1) at (x, d): dpi/dq * t with q = R K^-1 (u, v, 1) + d t. The
// reprojection must be valid (z > 0).
Eigen::Vector2d ReprojectionIdepthJacobian(const PinholeCamera& camera, const SE3& cur_from_ref,
                                           const Eigen::Vector2d& pixel_in_ref, double idepth);

// ---------------------------------------------------------------------------------------------
// Photometric residual r = I_ref(x) - I_cur(tau(x, d, xi)) (the paper's r_i, Sec. IV).

// Sigma_r = 2 sigma_I^2 + (dr/dd)^2 V, with dr/dd = -g^T J_d, where g is the current image's
// gradient at tau and J_d = ReprojectionIdepthJacobian (semi-dense VO, Engel et al. ICCV 2013;
// LSD-SLAM's SE3Tracker::calcWeightsAndResidual). The factor 2 counts the independent noise of
// both images. `sigma_intensity` in gray levels, `idepth_var` in (1/m)^2.
// Bilinear interpolation at a sub-pixel position averages the pixel noise (variance factor
// sum w_i^2 in [1/4, 1]), so 2 sigma_I^2 is an upper bound on the image term; see the docs.
double PhotometricVariance(double sigma_intensity, const Eigen::Vector2d& gradient_cur,
                           const Eigen::Vector2d& pixel_idepth_jacobian, double idepth_var);

// ---------------------------------------------------------------------------------------------
// Lines.

// A current-frame image line l = (a, b, c), a^2 + b^2 = 1, with its 3x3 covariance (rank 2: the
// normalisation removes one degree of freedom).
struct LineWithCovariance {
  Eigen::Vector3d line = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
};

// The line through endpoints p1, p2 (pixels): l = (p1; 1) x (p2; 1) / |(a, b)|, so that
// l^T (u, v, 1) is the signed distance in pixels, positive on the side the normal
// (a, b) = (y1 - y2, x2 - x1) / |p2 - p1| points to (swapping p1 and p2 flips the sign). Its
// covariance propagates isotropic endpoint noise N(0, sigma_px^2 I2) through the cross product and
// the normalisation (first order, analytic Jacobians): Sigma_l = sigma_px^2 J J^T, J = dl/d(p1, p2)
// (3x4). The angular part of Sigma_l falls as 1/length^2, so longer lines are trusted more. Throws
// std::invalid_argument when |p2 - p1| is below 1e-9 px or sigma_px < 0.
LineWithCovariance FitLine(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, double sigma_px);

// A 3x2 factor B of a line covariance with Sigma_l = B B^T (FitLine's Sigma_l has rank 2): the
// two largest eigenpairs, B = [v1 sqrt(e1), v2 sqrt(e2)] (negative round-off clamped to 0).
Eigen::Matrix<double, 3, 2> LineCovarianceFactor(const Eigen::Matrix3d& line_cov);

// Sigma_x' of the reprojected pixel from the inverse-depth variance: J_d V J_d^T (2x2),
// embedded as the top-left block of a 3x3 homogeneous covariance (third row and column zero),
// ready for PointToLineVariance.
Eigen::Matrix3d ReprojectedPixelCovariance(const Eigen::Vector2d& pixel_idepth_jacobian,
                                           double idepth_var);
// Convenience: the same from the geometry (calls ReprojectionIdepthJacobian).
Eigen::Matrix3d ReprojectedPixelCovariance(const PinholeCamera& camera, const SE3& cur_from_ref,
                                           const Eigen::Vector2d& pixel_in_ref, double idepth,
                                           double idepth_var);

// Point-to-line residual g = l^T x' (the paper's g_j, x' = (u, v, 1) the reprojected pixel):
// Sigma_g = l^T Sigma_x' l + x'^T Sigma_l x' (independent line and point errors; the product
// term of the two errors is second order and dropped).
double PointToLineVariance(const Eigen::Vector3d& line, const Eigen::Matrix3d& line_cov,
                           const Eigen::Vector2d& pixel_cur, const Eigen::Matrix3d& pixel_cov);

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_COVARIANCE_MODELS_H_
