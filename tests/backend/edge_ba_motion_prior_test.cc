// EdgeBAMotionPrior (backend/edge_ba/edge_ba_motion_prior.h): zero at the measured relative pose,
// the whitened translation / rotation error of a known perturbation, automatic-differentiation
// Jacobians against numeric differences through SE3Manifold; and the problem builder
// adds one prior per consecutive keyframe pair that carries a tracked relative pose.
#include "backend/edge_ba/edge_ba_motion_prior.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "backend/edge_ba/edge_ba_problem_builder.h"
#include "experiments/evaluation/edge_ba_simulation.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

SE3 CamAFromWorld() {
  Vector6d twist;
  twist << 0.3, -0.2, 0.4, 0.15, -0.25, 0.1;
  return SE3::Exp(twist);
}

SE3 CamBFromWorld() {
  Vector6d twist;
  twist << 0.1, 0.05, 0.2, 0.05, -0.3, 0.2;
  return SE3::Exp(twist) * CamAFromWorld();
}

std::vector<double> Residuals(const SE3& cam_a_from_world, const SE3& cam_b_from_world,
                              const SE3& a_from_b_measured, double sigma_t, double sigma_r) {
  double a[7], b[7];
  PoseToParameters(cam_a_from_world, a);
  PoseToParameters(cam_b_from_world, b);
  std::unique_ptr<ceres::CostFunction> cost(
      EdgeBAMotionPrior::Create(a_from_b_measured, sigma_t, sigma_r));
  std::vector<double> residuals(6);
  const double* parameters[] = {a, b};
  EXPECT_TRUE(cost->Evaluate(parameters, residuals.data(), nullptr));
  return residuals;
}

TEST(EdgeBAMotionPriorTest, ZeroAtMeasurementAndWhitenedError) {
  const SE3 a_from_b = CamAFromWorld() * CamBFromWorld().Inverse();
  // Residuals are exact to rounding (~1e-15 of O(1) values); 1e-12 is far below any error.
  for (double r : Residuals(CamAFromWorld(), CamBFromWorld(), a_from_b, 0.01, 0.002)) {
    EXPECT_NEAR(r, 0.0, 1e-12);
  }
  // Camera b moved by 3 mm along its own x axis: E = a_from_b_meas^-1 a_from_b_est is then a
  // pure translation of (3 mm, 0, 0), whitened by sigma_t = 1 cm.
  const SE3 moved(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.003, 0.0, 0.0));
  std::vector<double> r =
      Residuals(CamAFromWorld(), moved * CamBFromWorld(), a_from_b, 0.01, 0.002);
  EXPECT_NEAR(r[0], 0.3, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  EXPECT_NEAR(r[2], 0.0, 1e-9);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(r[i], 0.0, 1e-9);
  // Camera b rotated by 1 mrad about its z axis: rotation error 1 mrad, whitened by 2 mrad
  // (2 vec(q) is exact to O(angle^3) = 1e-9 here).
  const SE3 turned(Eigen::Quaterniond(Eigen::AngleAxisd(-1e-3, Eigen::Vector3d::UnitZ())),
                   Eigen::Vector3d::Zero());
  r = Residuals(CamAFromWorld(), turned * CamBFromWorld(), a_from_b, 0.01, 0.002);
  EXPECT_NEAR(r[5], 0.5, 1e-6);
  EXPECT_NEAR(r[3], 0.0, 1e-9);
  EXPECT_NEAR(r[4], 0.0, 1e-9);
}

// Tangent-space Jacobians against Ridders' differences from a 1e-5 relative step. Some entries
// are exactly zero (the translation error does not depend on camera b's rotation under a left
// twist) and come out as ~1e-11 numerically, which GradientChecker's per-entry relative test
// rejects; so the check is the largest absolute difference relative to the block's largest
// entry. The residual is smooth and Ridders is accurate to ~1e-9 relative; 1e-6 leaves margin.
TEST(EdgeBAMotionPriorTest, JacobiansMatchNumericDifferences) {
  const SE3 a_from_b_measured =
      SE3::Exp((Vector6d() << 0.02, 0.01, -0.01, 0.01, 0.02, -0.01).finished()) * CamAFromWorld() *
      CamBFromWorld().Inverse();
  std::unique_ptr<ceres::CostFunction> cost(
      EdgeBAMotionPrior::Create(a_from_b_measured, 0.01, 0.002));
  double a[7], b[7];
  PoseToParameters(CamAFromWorld(), a);
  PoseToParameters(CamBFromWorld(), b);
  const SE3Manifold manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&manifold, &manifold};
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-5;
  const ceres::GradientChecker checker(cost.get(), &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  const double* parameters[] = {a, b};
  checker.Probe(parameters, 1e-6, &results);
  ASSERT_EQ(results.local_jacobians.size(), 2u);
  for (int block = 0; block < 2; ++block) {
    const Eigen::MatrixXd& analytic = results.local_jacobians[block];
    const Eigen::MatrixXd& numeric = results.local_numeric_jacobians[block];
    ASSERT_EQ(analytic.rows(), 6);
    ASSERT_EQ(analytic.cols(), 6);
    const double scale = analytic.cwiseAbs().maxCoeff();
    EXPECT_GT(scale, 1.0);
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-6 * scale) << "block " << block;
  }
}

TEST(EdgeBAMotionPriorTest, BuilderAddsOnePriorPerTrackedPair) {
  const PinholeCamera camera{640, 480, 525.0, 525.0, 319.5, 239.5};
  const EdgeBAScene scene = MakeRandomLineScene(60, 4, 0.5, 1);
  EdgeBAWindow window =
      SimulateEdgeBAWindow(camera, scene.world_from_cam, scene.start, scene.end, {}).window;
  ASSERT_EQ(window.keyframes.size(), 4u);
  for (size_t k = 1; k < window.keyframes.size(); ++k) {
    window.keyframes[k].has_motion_prior = true;
    window.keyframes[k].previous_from_this =
        window.keyframes[k - 1].cam_from_world * window.keyframes[k].cam_from_world.Inverse();
  }
  window.keyframes[1].has_motion_prior = false;
  EdgeBAOptions options;
  const int expected = static_cast<int>(window.keyframes.size()) - 2;
  EXPECT_EQ(EdgeBAProblemBuilder(options).Build(window).num_motion_priors, expected);
  options.motion_prior = false;
  EXPECT_EQ(EdgeBAProblemBuilder(options).Build(window).num_motion_priors, 0);
}

}  // namespace
}  // namespace pldvo
