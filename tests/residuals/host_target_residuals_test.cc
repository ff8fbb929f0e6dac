// The host-target residuals of windowed bundle adjustment (residuals/host_target_*_residual.h):
// analytic Jacobians of every block against ceres::GradientChecker through the manifolds, the
// values against the frame-to-keyframe residuals they generalise, and the invalid rows.
// Breaking them: a wrong sign or a dropped term in any block's Jacobian (e.g. the host pose's
// -d R_th part, or e^{s} for e^{-s} in the brightness) fails the GradientChecker tests by far
// more than their bounds; a wrong relative pose (T_hw T_tw^-1) fails the value tests.
#include <ceres/gradient_checker.h>
#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "residuals/covariance_models.h"
#include "residuals/host_target_photometric_residual.h"
#include "residuals/host_target_point_to_line_residual.h"
#include "residuals/photometric_residual.h"
#include "residuals/point_to_line_residual.h"
#include "residuals/se3_manifold.h"
#include "tests/residuals/residual_test_utils.h"

namespace pldvo {
namespace {

using testing_utils::PlaceReferencePixel;
using testing_utils::SampleImage;
using testing_utils::SmoothIntensity;
using testing_utils::TestCamera;

// A host and a target pose in a world frame that is neither of them: target_from_host is
// TestCurFromRef (12 cm, 0.06 rad).
SE3 HostFromWorld() {
  Vector6d twist;
  twist << -0.3, 0.1, 0.2, 0.05, 0.02, -0.04;
  return SE3::Exp(twist);
}
SE3 TargetFromWorld() { return testing_utils::TestCurFromRef() * HostFromWorld(); }

// Checks every block; returns the worst error relative to the largest entry of its row, over
// all blocks. GradientChecker's own per-entry criterion gets `entry_tolerance`.
double GradientCheck(const ceres::CostFunction& cost, const std::vector<const double*>& parameters,
                     double entry_tolerance) {
  const SE3Manifold se3;
  std::vector<const ceres::Manifold*> manifolds(parameters.size(), nullptr);
  manifolds[0] = &se3;
  manifolds[1] = &se3;
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-5;
  const ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(parameters.data(), entry_tolerance, &results)) << results.error_log;
  double worst_row = 0.0;
  for (size_t b = 0; b < parameters.size(); ++b) {
    const Eigen::MatrixXd& analytic = results.local_jacobians[b];
    const Eigen::MatrixXd& numeric = results.local_numeric_jacobians[b];
    for (int i = 0; i < analytic.rows(); ++i) {
      const double scale = analytic.row(i).cwiseAbs().maxCoeff();
      if (scale == 0.0) continue;
      worst_row =
          std::max(worst_row, (analytic.row(i) - numeric.row(i)).cwiseAbs().maxCoeff() / scale);
    }
  }
  return worst_row;
}

class HostTargetResidualsTest : public ::testing::Test {
 protected:
  HostTargetResidualsTest()
      : camera_(TestCamera()), target_(SampleImage(camera_, SmoothIntensity), 1) {
    PoseToParameters(HostFromWorld(), host_pose_);
    PoseToParameters(TargetFromWorld(), target_pose_);
  }

  // A pattern of host pixels around the point that reprojects to `pixel_in_target` at depth
  // 2.5 m, with host intensities offset from the target's so that rows span both Huber zones.
  std::vector<HostPixel> MakePattern(const Eigen::Vector2d& pixel_in_target, double* idepth) {
    Eigen::Vector2d centre;
    PlaceReferencePixel(camera_, testing_utils::TestCurFromRef(), pixel_in_target, 2.5, &centre,
                        idepth);
    std::vector<HostPixel> pattern;
    const int offsets[][2] = {{0, -2}, {-1, -1}, {1, -1}, {-2, 0}, {0, 0}, {2, 0}, {-1, 1}, {0, 2}};
    int k = 0;
    for (const auto& offset : offsets) {
      HostPixel p;
      p.pixel_in_host = centre + Eigen::Vector2d(offset[0], offset[1]);
      p.intensity_host =
          SmoothIntensity(pixel_in_target.x(), pixel_in_target.y()) + (k % 2 == 0 ? 3.0 : -9.0);
      p.sqrt_info = 0.2 + 0.02 * k;
      pattern.push_back(p);
      ++k;
    }
    return pattern;
  }

  PinholeCamera camera_;
  ImagePyramid target_;
  double host_pose_[7];
  double target_pose_[7];
};

// Bicubic sampling: the rows are C1 in every parameter and the Jacobians exact, so the check is
// tight: measured worst row-relative error 2e-10 over the five blocks; a difference that
// straddles a cell boundary can reach 3.6e-5 (photometric_residual_test.cc, same image and
// step). Bounds 1e-3 per entry and 1e-4 per row, with and without the Huber loss inside, at
// generic brightness.
TEST_F(HostTargetResidualsTest, PhotometricGradientCheckerAllBlocks) {
  const ceres::HuberLoss huber(1.345);
  for (const ceres::LossFunction* loss : {static_cast<const ceres::LossFunction*>(nullptr),
                                          static_cast<const ceres::LossFunction*>(&huber)}) {
    for (const Eigen::Vector2d& pixel :
         {Eigen::Vector2d(40.3, 30.7), Eigen::Vector2d(100.6, 80.2), Eigen::Vector2d(77.1, 55.9)}) {
      double idepth = 0.0;
      const HostTargetPhotometricResidual cost(target_, 0, camera_, MakePattern(pixel, &idepth),
                                               loss, ImageInterpolation::kBicubic);
      const double host_brightness[2] = {0.08, 4.0};
      const double target_brightness[2] = {-0.05, -6.0};
      const double worst = GradientCheck(
          cost, {host_pose_, target_pose_, &idepth, host_brightness, target_brightness}, 1e-3);
      EXPECT_LT(worst, 1e-4);
    }
  }
}

// With host = world (identity host pose) and the host's brightness at the origin, the rows are
// PhotometricResidual's (affine, cur_from_ref = target pose, {a, b} = target brightness) row by
// row, value and pose Jacobian, for bilinear sampling too. Agreement to rounding (1e-9).
TEST_F(HostTargetResidualsTest, PhotometricEqualsFrameToKeyframeRowsAtIdentityHost) {
  double identity[7];
  PoseToParameters(SE3(), identity);
  double idepth = 0.0;
  const std::vector<HostPixel> pattern = MakePattern({60.2, 44.4}, &idepth);
  std::vector<PhotometricObservation> observations;
  for (const HostPixel& p : pattern) {
    PhotometricObservation o;
    o.pixel_in_ref = p.pixel_in_host;
    o.idepth = idepth;
    o.intensity_ref = p.intensity_host;
    o.sqrt_info = p.sqrt_info;
    observations.push_back(o);
  }
  double cur_from_ref[7];
  PoseToParameters(testing_utils::TestCurFromRef(), cur_from_ref);
  const double host_brightness[2] = {0.0, 0.0};
  const double target_brightness[2] = {0.12, -5.0};
  const HostTargetPhotometricResidual windowed(target_, 0, camera_, pattern);
  const PhotometricResidual tracking(target_, 0, camera_, observations, nullptr,
                                     ImageInterpolation::kBilinear, BrightnessModel::kAffine);
  const int n = static_cast<int>(pattern.size());
  std::vector<double> r_windowed(n), r_tracking(n), j_target(n * 7), j_tracking(n * 7),
      j_brightness(n * 2), j_tracking_brightness(n * 2);
  const double* windowed_parameters[] = {identity, cur_from_ref, &idepth, host_brightness,
                                         target_brightness};
  double* windowed_jacobians[] = {nullptr, j_target.data(), nullptr, nullptr, j_brightness.data()};
  ASSERT_TRUE(windowed.Evaluate(windowed_parameters, r_windowed.data(), windowed_jacobians));
  const double* tracking_parameters[] = {cur_from_ref, target_brightness};
  double* tracking_jacobians[] = {j_tracking.data(), j_tracking_brightness.data()};
  ASSERT_TRUE(tracking.Evaluate(tracking_parameters, r_tracking.data(), tracking_jacobians));
  for (int k = 0; k < n; ++k) {
    EXPECT_NEAR(r_windowed[k], r_tracking[k], 1e-9);
    EXPECT_NE(r_windowed[k], 0.0);
  }
  for (int i = 0; i < n * 7; ++i) EXPECT_NEAR(j_target[i], j_tracking[i], 1e-9);
  for (int i = 0; i < n * 2; ++i) EXPECT_NEAR(j_brightness[i], j_tracking_brightness[i], 1e-9);
}

// The brightness model: a target image that is exactly e^{a_t - a_h} (I_h - b_h) + b_t of the
// host intensities gives zero rows (to the float32 storage of the image, 1e-4 gray levels).
TEST_F(HostTargetResidualsTest, PhotometricIsZeroUnderTheAffineTransfer) {
  const double a_h = 0.1, b_h = 5.0, a_t = -0.2, b_t = 12.0;
  double idepth = 0.0;
  std::vector<HostPixel> pattern = MakePattern({70.0, 50.0}, &idepth);
  const SE3 target_from_host = testing_utils::TestCurFromRef();
  for (HostPixel& p : pattern) {
    Eigen::Vector2d pixel_in_target;
    ASSERT_TRUE(Reproject(camera_, target_from_host, p.pixel_in_host, idepth, &pixel_in_target));
    const double intensity_target =
        target_.SampleIntensity(0, pixel_in_target.x(), pixel_in_target.y());
    p.intensity_host = std::exp(a_h - a_t) * (intensity_target - b_t) + b_h;
    p.sqrt_info = 1.0;
  }
  const HostTargetPhotometricResidual cost(target_, 0, camera_, pattern);
  const double host_brightness[2] = {a_h, b_h};
  const double target_brightness[2] = {a_t, b_t};
  const double* parameters[] = {host_pose_, target_pose_, &idepth, host_brightness,
                                target_brightness};
  std::vector<double> residuals(pattern.size());
  ASSERT_TRUE(cost.Evaluate(parameters, residuals.data(), nullptr));
  for (double r : residuals) EXPECT_NEAR(r, 0.0, 1e-4);
}

// A point behind the target camera, or reprojecting outside the sampling area, gives rows and
// Jacobians of 0.
TEST_F(HostTargetResidualsTest, InvalidRowsAreZero) {
  double idepth = 0.0;
  std::vector<HostPixel> pattern = MakePattern({157.0, 60.0}, &idepth);  // the +2 px pixel: outside
  const HostTargetPhotometricResidual cost(target_, 0, camera_, pattern);
  const double brightness[2] = {0.0, 0.0};
  const double* parameters[] = {host_pose_, target_pose_, &idepth, brightness, brightness};
  const int n = static_cast<int>(pattern.size());
  std::vector<double> residuals(n), j0(n * 7, 1.0), j1(n * 7, 1.0), j2(n, 1.0), j3(n * 2, 1.0),
      j4(n * 2, 1.0);
  double* jacobians[] = {j0.data(), j1.data(), j2.data(), j3.data(), j4.data()};
  ASSERT_TRUE(cost.Evaluate(parameters, residuals.data(), jacobians));
  int invalid = 0;
  for (int k = 0; k < n; ++k) {
    if (residuals[k] != 0.0) continue;
    ++invalid;
    for (int c = 0; c < 7; ++c) EXPECT_EQ(j0[k * 7 + c], 0.0);
    EXPECT_EQ(j2[k], 0.0);
  }
  EXPECT_GE(invalid, 1);  // u ~ 159 is outside [1, w - 2) = [1, 158)
  EXPECT_LT(invalid, n);
  // Behind the target: a point 2 m behind the host seen from a target turned by 180 degrees.
  double behind_pose[7];
  Vector6d twist;
  twist << 0.0, 0.0, 0.0, 0.0, M_PI, 0.0;
  PoseToParameters(SE3::Exp(twist) * HostFromWorld(), behind_pose);
  const double* behind[] = {host_pose_, behind_pose, &idepth, brightness, brightness};
  ASSERT_TRUE(cost.Evaluate(behind, residuals.data(), jacobians));
  for (int k = 0; k < n; ++k) EXPECT_EQ(residuals[k], 0.0);
}

// Point-to-line: GradientChecker over the three blocks, with and without a row-wise Huber loss.
// Exact geometry: measured worst row-relative error 1.5e-10; bound 1e-6.
TEST_F(HostTargetResidualsTest, PointToLineGradientCheckerAllBlocks) {
  const ceres::HuberLoss huber(1.345);
  const Eigen::Vector3d line = Eigen::Vector3d(0.6, 0.8, -70.0);  // a^2 + b^2 = 1
  for (const ceres::LossFunction* loss : {static_cast<const ceres::LossFunction*>(nullptr),
                                          static_cast<const ceres::LossFunction*>(&huber)}) {
    for (const Eigen::Vector2d& pixel :
         {Eigen::Vector2d(40.3, 30.7), Eigen::Vector2d(100.6, 80.2)}) {
      Eigen::Vector2d pixel_in_host;
      double idepth = 0.0;
      PlaceReferencePixel(camera_, testing_utils::TestCurFromRef(), pixel, 2.5, &pixel_in_host,
                          &idepth);
      const HostTargetPointToLineResidual cost(camera_, pixel_in_host, line, 0.7, loss);
      const double worst = GradientCheck(cost, {host_pose_, target_pose_, &idepth}, 1e-5);
      EXPECT_LT(worst, 1e-6);
    }
  }
}

// With host = world the row is PointToLineResidual's (eq. 3) for cur_from_ref = target pose:
// value and pose Jacobian to rounding. A point 2 px off the line gives 2 sqrt_info.
TEST_F(HostTargetResidualsTest, PointToLineEqualsFrameToKeyframeRowAtIdentityHost) {
  double identity[7];
  PoseToParameters(SE3(), identity);
  double cur_from_ref[7];
  PoseToParameters(testing_utils::TestCurFromRef(), cur_from_ref);
  Eigen::Vector2d pixel_in_host;
  double idepth = 0.0;
  PlaceReferencePixel(camera_, testing_utils::TestCurFromRef(), {80.0, 60.0}, 3.0, &pixel_in_host,
                      &idepth);
  const Eigen::Vector3d line(1.0, 0.0, -78.0);  // u = 78: the point is 2 px to its right
  const HostTargetPointToLineResidual windowed(camera_, pixel_in_host, line, 0.5);
  PointToLineObservation o;
  o.pixel_in_ref = pixel_in_host;
  o.idepth = idepth;
  o.line_in_cur = line;
  o.sqrt_info = 0.5;
  const PointToLineResidual tracking(camera_, {o});
  double r_windowed = 0.0, r_tracking = 0.0;
  double j_windowed[7], j_tracking[7];
  const double* windowed_parameters[] = {identity, cur_from_ref, &idepth};
  double* windowed_jacobians[] = {nullptr, j_windowed, nullptr};
  ASSERT_TRUE(windowed.Evaluate(windowed_parameters, &r_windowed, windowed_jacobians));
  const double* tracking_parameters[] = {cur_from_ref};
  double* tracking_jacobians[] = {j_tracking};
  ASSERT_TRUE(tracking.Evaluate(tracking_parameters, &r_tracking, tracking_jacobians));
  EXPECT_NEAR(r_windowed, 1.0, 1e-9);
  EXPECT_NEAR(r_windowed, r_tracking, 1e-12);
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(j_windowed[i], j_tracking[i], 1e-12);
}

TEST_F(HostTargetResidualsTest, RejectsBadInput) {
  EXPECT_THROW(HostTargetPhotometricResidual(target_, 0, camera_, {}), std::invalid_argument);
  EXPECT_THROW(HostTargetPhotometricResidual(target_, 1, camera_, {HostPixel()}),
               std::invalid_argument);
  HostPixel negative;
  negative.sqrt_info = -1.0;
  EXPECT_THROW(HostTargetPhotometricResidual(target_, 0, camera_, {negative}),
               std::invalid_argument);
  EXPECT_THROW(HostTargetPointToLineResidual(camera_, {10.0, 10.0}, {1.0, 1.0, 0.0}, 1.0),
               std::invalid_argument);
  EXPECT_THROW(HostTargetPointToLineResidual(camera_, {10.0, 10.0}, {1.0, 0.0, 0.0}, -1.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
