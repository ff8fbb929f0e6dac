// Synthetic scenes shared by the residual tests: a smooth analytic image sampled into an
// ImagePyramid, a camera, a generic pose and reference pixels placed so that they reproject to
// chosen current-frame positions.
#ifndef PLDVO_TESTS_RESIDUALS_RESIDUAL_TEST_UTILS_H_
#define PLDVO_TESTS_RESIDUALS_RESIDUAL_TEST_UTILS_H_

#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <Eigen/Core>
#include <cmath>
#include <opencv2/core.hpp>
#include <random>

#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace testing_utils {

inline PinholeCamera TestCamera() { return PinholeCamera{160, 120, 140.0, 135.0, 79.5, 59.5}; }

// A smooth texture: wavelengths 29..53 px, gradients of about 10 gray levels per pixel.
inline double SmoothIntensity(double x, double y) {
  constexpr double kTwoPi = 6.283185307179586;
  return 128.0 + 50.0 * std::sin(kTwoPi * x / 37.0 + 0.3) * std::cos(kTwoPi * y / 29.0 - 0.2) +
         30.0 * std::sin(kTwoPi * (x + 2.0 * y) / 53.0);
}

// A linear ramp: bilinear interpolation and central differences are exact on it, so the
// analytic Jacobian equals the derivative of the interpolated residual exactly.
inline double RampIntensity(double x, double y) { return 40.0 + 0.9 * x + 0.6 * y; }

template <typename Function>
cv::Mat SampleImage(const PinholeCamera& camera, Function function) {
  cv::Mat image(camera.height, camera.width, CV_32F);
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      image.at<float>(y, x) = static_cast<float>(function(x, y));
    }
  }
  return image;
}

// A generic pose cur_from_ref: 0.06 rad about a skew axis, 12 cm translation.
inline SE3 TestCurFromRef() {
  Vector6d twist;
  twist << 0.09, -0.05, 0.06, 0.03, -0.04, 0.025;
  return SE3::Exp(twist);
}

// A reference pixel and its inverse depth that reproject (with cur_from_ref) to pixel_in_cur
// at depth `depth_in_cur` in the current frame.
inline void PlaceReferencePixel(const PinholeCamera& camera, const SE3& cur_from_ref,
                                const Eigen::Vector2d& pixel_in_cur, double depth_in_cur,
                                Eigen::Vector2d* pixel_in_ref, double* idepth) {
  const Eigen::Vector3d point_in_cur = depth_in_cur * camera.Unproject(pixel_in_cur);
  const Eigen::Vector3d point_in_ref = cur_from_ref.Inverse() * point_in_cur;
  *pixel_in_ref = camera.Project(point_in_ref);
  *idepth = 1.0 / point_in_ref.z();
}

// Jet-aware intensity sampler for autodiff twins: the value is the bilinear intensity and the
// derivative is the bilinearly interpolated precomputed gradient, i.e. exactly the model of the
// analytic Jacobians.
inline double SampleIntensity(const ImagePyramid& pyramid, int level, double u, double v) {
  return pyramid.Sample(level, u, v)[0];
}
template <typename T, int N>
ceres::Jet<T, N> SampleIntensity(const ImagePyramid& pyramid, int level, const ceres::Jet<T, N>& u,
                                 const ceres::Jet<T, N>& v) {
  const Eigen::Vector3f sample = pyramid.Sample(level, u.a, v.a);
  ceres::Jet<T, N> result;
  result.a = static_cast<double>(sample[0]);
  result.v = static_cast<double>(sample[1]) * u.v + static_cast<double>(sample[2]) * v.v;
  return result;
}

// Templated twins of the row-wise square-root robustification (residuals/robustify.h) for
// Ceres' HuberLoss(a) and CauchyLoss(a).
template <typename T>
T HuberSqrtForm(const T& r, double a) {
  using std::sqrt;
  const T s = r * r;
  const T rho = s <= T(a * a) ? s : T(2.0 * a) * sqrt(s) - T(a * a);
  return r >= T(0.0) ? sqrt(rho) : -sqrt(rho);
}
template <typename T>
T CauchySqrtForm(const T& r, double a) {
  using std::log;
  using std::sqrt;
  const double b = a * a;
  const T rho = T(b) * log(T(1.0) + r * r / T(b));
  return r >= T(0.0) ? sqrt(rho) : -sqrt(rho);
}

// An analytic pose cost function of n rows against its autodiff twin at one pose (7 parameters):
// both Jacobians lifted to the tangent space, and the largest differences.
struct TwinComparison {
  bool evaluated = false;  // both Evaluate calls returned true
  Eigen::VectorXd residuals;
  Eigen::MatrixXd tangent_jacobian;  // of `analytic`, n x 6
  double max_residual_difference = 0.0;
  double max_tangent_difference = 0.0;
  double tangent_scale = 0.0;  // largest |entry| of the twin's tangent Jacobian
};

inline TwinComparison CompareWithTwin(const ceres::CostFunction& analytic,
                                      const ceres::CostFunction& twin, const double* pose, int n) {
  TwinComparison comparison;
  Eigen::VectorXd r_twin(n);
  comparison.residuals.resize(n);
  Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> j_analytic(n, 7), j_twin(n, 7);
  const double* parameters[] = {pose};
  double* j_analytic_ptr[] = {j_analytic.data()};
  double* j_twin_ptr[] = {j_twin.data()};
  comparison.evaluated =
      analytic.Evaluate(parameters, comparison.residuals.data(), j_analytic_ptr) &&
      twin.Evaluate(parameters, r_twin.data(), j_twin_ptr);
  if (!comparison.evaluated) return comparison;
  const PlusJacobianMatrix plus = PosePlusJacobian(pose);
  comparison.tangent_jacobian = j_analytic * plus;
  const Eigen::MatrixXd tangent_twin = j_twin * plus;
  comparison.max_residual_difference = (comparison.residuals - r_twin).cwiseAbs().maxCoeff();
  comparison.max_tangent_difference =
      (comparison.tangent_jacobian - tangent_twin).cwiseAbs().maxCoeff();
  comparison.tangent_scale = tangent_twin.cwiseAbs().maxCoeff();
  return comparison;
}

}  // namespace testing_utils
}  // namespace pldvo

#endif  // PLDVO_TESTS_RESIDUALS_RESIDUAL_TEST_UTILS_H_
