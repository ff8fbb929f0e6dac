// Photometric residual of a batch of reference pixels against the current image
// (Yang & Scherer, ICRA 2017, Sec. IV: the photometric term r_i of eq. 2, weighted by the variance
// Sigma_f of eq. 5, the semi-dense VO observation model; see docs/residuals.md):
//
//   r_i = sqrt_info_i * (I_ref(x_i) - I_cur(tau(x_i, d_i, xi))),   i = 1..N,
//   tau(x, d, xi) = pi(T(xi) pi^-1(x, d)),
//
// computed as pi(R K^-1 (x; 1) + d t) (valid for d = 0, a point at infinity).
//
// With BrightnessModel::kAffine (residuals/affine_brightness.h) the row is, in symmetric form,
//
//   r_i = sqrt_info_i * e^{-a/2} (e^a I_ref(x_i) + b - I_cur(tau(x_i, d_i, xi)))
//
// (the same rows when a = b = 0). Both images are noisy: with e^a I_ref + b - I_cur the
// least-squares gain would be the ordinary regression slope of I_cur on I_ref, which the noise
// of I_ref attenuates (docs/tracking.md, affine brightness); the factor
// e^{-a/2} treats the two images alike and makes it sqrt(S_cur / S_ref) (reduced major axis),
// exact at unit gain when both have the same noise.
//
// Parameter blocks: the pose, double[7] = [t; q] = cur_from_ref (residuals/se3_manifold.h; use
// SE3Manifold), and with kAffine the brightness double[2] = {a, b} (Euclidean; dr_i/da =
// sqrt_info_i (e^{a/2} I_ref - e^{-a/2} (b - I_cur)) / 2, dr_i/db = sqrt_info_i e^{-a/2}, and
// the pose Jacobian below times e^{-a/2}). Jacobian in the tangent space (left twist,
// translation first):
//   dr_i/dxi = -sqrt_info_i g^T dpi/dp [I, -[p']x],  p' = cur_from_ref * pi^-1(x_i, d_i),
// lifted to the 7 parameters by J_tangent * MinusJacobian(x). I_cur and g = (Ix, Iy) depend on
// the interpolation (ImageInterpolation, config `tracking.problem.interpolation`):
//   kBilinear  I_cur is the bilinear interpolant of the level, g the bilinearly interpolated
//              precomputed central-difference gradient (ImagePyramid; one lookup of [I, Ix, Iy],
//              as DSO). The cost is only C0 (its derivative jumps where a reprojection crosses a
//              pixel-cell boundary) and g is not the derivative of I_cur.
//   kBicubic   I_cur is Keys' cubic convolution (a = -1/2, Catmull-Rom) of the level's 4x4
//              neighbourhood, ceres::BiCubicInterpolator over a ceres::Grid2D<float> of the
//              level's intensity plane, and g = (dI_cur/dx, dI_cur/dy) is its exact derivative.
//              The interpolant is C1, so the cost is C1 in the pose and the Jacobian is exactly
//              its derivative: descent methods agree on the minimum. 16 samples instead of 4.
//
// Weighting: sqrt_info_i is given by the caller, computed at the linearisation point from the
// covariance model (PhotometricVariance; see residuals/weighting.h) and held constant inside a
// solve.
//
// Robust loss (optional, not owned, must outlive this object): applied ROW-WISE inside the cost
// function in square-root form on the whitened residual r = r_i,
//   r~ = sign(r) sqrt(rho(r^2)),   dr~/dr = rho'(r^2) |r| / sqrt(rho(r^2))  (-> sqrt(rho'(0)) = 1
// as r -> 0), so sum_i r~_i^2 = sum_i rho(r_i^2) exactly and the gradient of the cost is exactly
// that of the robust cost; every pixel of a batch keeps its own robustness. With N = 1 the
// caller may instead pass the loss to ceres::Problem::AddResidualBlock (and nullptr here); do
// not do both.
//
// Validity: a row whose reprojection falls behind the camera (z <= 0) or outside the sampling
// area [1, w - 2) x [1, h - 2) of the level (where the precomputed gradient is defined and the
// bicubic 4x4 neighbourhood lies inside the image, so neither clamps at the border) gets
// residual 0 and Jacobian row 0, and valid(i) == false. valid() reflects the most recent
// Evaluate() call (which may be a rejected trial step of the solver); it is not thread-safe
// when one object is shared by several residual blocks. EvaluateTangent() writes validity to a
// caller buffer instead and is const-thread-safe.
//
// Evaluate() does no heap allocation. The current pyramid must outlive this object.
#ifndef PLDVO_RESIDUALS_PHOTOMETRIC_RESIDUAL_H_
#define PLDVO_RESIDUALS_PHOTOMETRIC_RESIDUAL_H_

#include <ceres/cost_function.h>
#include <ceres/cubic_interpolation.h>
#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/image_pyramid.h"
#include "core/options.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/affine_brightness.h"
#include "residuals/pose_tangent_cost_function.h"

namespace pldvo {

// How I_cur and its gradient are sampled at a reprojection (see the header comment).
enum class ImageInterpolation { kBilinear, kBicubic };

inline const ChoiceNames<ImageInterpolation>& ImageInterpolationNames() {
  static const ChoiceNames<ImageInterpolation> names = {{"bilinear", ImageInterpolation::kBilinear},
                                                        {"bicubic", ImageInterpolation::kBicubic}};
  return names;
}

// One reference pixel of the photometric batch.
struct PhotometricObservation {
  Eigen::Vector2d pixel_in_ref = Eigen::Vector2d::Zero();  // at the residual's pyramid level
  double idepth = 0.0;                                     // inverse depth in ref, >= 0
  double intensity_ref = 0.0;                              // I_ref(x), gray levels
  double sqrt_info = 1.0;                                  // 1 / sqrt(Sigma_r), >= 0
};

class PhotometricResidual : public ceres::CostFunction, public PoseTangentCostFunction {
 public:
  // `camera` is the camera of `level` (PinholeCamera::AtLevel). Throws std::invalid_argument on
  // an empty batch, a level outside the pyramid, a camera whose size differs from the level's,
  // or a non-finite / negative idepth or sqrt_info.
  PhotometricResidual(const ImagePyramid& cur_pyramid, int level, const PinholeCamera& camera,
                      std::vector<PhotometricObservation> observations,
                      const ceres::LossFunction* loss = nullptr,
                      ImageInterpolation interpolation = ImageInterpolation::kBilinear,
                      BrightnessModel brightness = BrightnessModel::kNone);

  static PhotometricResidual* Create(
      const ImagePyramid& cur_pyramid, int level, const PinholeCamera& camera,
      std::vector<PhotometricObservation> observations, const ceres::LossFunction* loss = nullptr,
      ImageInterpolation interpolation = ImageInterpolation::kBilinear,
      BrightnessModel brightness = BrightnessModel::kNone) {
    return new PhotometricResidual(cur_pyramid, level, camera, std::move(observations), loss,
                                   interpolation, brightness);
  }

  // parameters[0] = cur_from_ref (7), with kAffine parameters[1] = {a, b}. jacobians[0], if
  // requested, is N x 7 row-major, jacobians[1] N x 2.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // The rows of Evaluate() with the pose Jacobian in the tangent space (N x 6 row-major).
  bool EvaluatePoseTangent(double const* const* parameters, double* residuals,
                           double* jacobian_tangent) const override;

  // The same rows for a pose given as SE3 and a = b = 0, with the Jacobian in the tangent space
  // (N x 6 row-major, may be nullptr) and validity written to `valid` (N entries, may be
  // nullptr). For Gauss-Newton solvers that work in the tangent space directly.
  void EvaluateTangent(const SE3& cur_from_ref, double* residuals, double* jacobian_tangent,
                       std::uint8_t* valid) const;

  // The unweighted intensity errors e_i = I_ref(x_i) - I_cur(tau(x_i, d_i, xi)) for a pose: the
  // rows without sqrt_info and without the robust loss (the tracker's intensity correlation),
  // with validity as in Evaluate (e_i = 0 where invalid). No heap allocation.
  void IntensityErrors(const SE3& cur_from_ref, double* errors, std::uint8_t* valid) const;

  // The reprojected pixels tau(x_i, d_i, xi) for a pose (the paper's Fig. 2 iteration images),
  // with their validity (same rule as in Evaluate); NaN behind the camera. Allocates; not for
  // hot loops.
  std::vector<Eigen::Vector2d> ReprojectedPixels(const SE3& cur_from_ref,
                                                 std::vector<std::uint8_t>* valid = nullptr) const;

  int num_observations() const { return static_cast<int>(observations_.size()); }
  const std::vector<PhotometricObservation>& observations() const { return observations_; }
  // Validity of row i after the most recent Evaluate() (see the header comment).
  bool valid(int i) const { return valid_[i] != 0; }
  int num_valid() const;

 private:
  // Evaluate() with the pose Jacobian lifted to the 7 parameters (jacobian_ambient) or in the
  // tangent (jacobian_tangent); each may be nullptr.
  void EvaluateRows(double const* const* parameters, double* residuals, double* jacobian_ambient,
                    double* jacobian_tangent, double* jacobian_brightness) const;

  using IntensityGrid = ceres::Grid2D<float, 1>;
  using BicubicInterpolator = ceres::BiCubicInterpolator<IntensityGrid>;

  const ImagePyramid& cur_pyramid_;
  const int level_;
  const PinholeCamera camera_;
  const std::vector<PhotometricObservation> observations_;
  // K^-1 (x; 1) of every observation, precomputed.
  std::vector<Eigen::Vector3d> rays_in_ref_;
  const ceres::LossFunction* loss_;
  const ImageInterpolation interpolation_;
  const BrightnessModel brightness_;
  // kBicubic only: the level's intensity plane and its interpolator (which refers to the grid).
  std::unique_ptr<const IntensityGrid> grid_;
  std::unique_ptr<const BicubicInterpolator> bicubic_;
  mutable std::vector<std::uint8_t> valid_;
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_PHOTOMETRIC_RESIDUAL_H_
