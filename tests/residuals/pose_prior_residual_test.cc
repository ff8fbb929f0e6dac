// PosePriorResidual: its squared norm / 2 is the quadratic energy it stands for, and its
// Jacobians pass ceres::GradientChecker away from the linearisation point (where the inverse
// left Jacobian of SE(3) is not the identity).
#include "residuals/pose_prior_residual.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

constexpr int kPoses = 3;

struct Prior {
  std::vector<SE3> linearization;
  Eigen::MatrixXd information;
  Eigen::VectorXd gradient;
};

// A random prior on three poses; the information has a 6-D null space (a gauge), as a
// marginalisation of relative constraints gives.
Prior RandomPrior(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Prior prior;
  for (int k = 0; k < kPoses; ++k) {
    Vector6d twist;
    for (int i = 0; i < 6; ++i) twist[i] = 0.5 * normal(*rng);
    prior.linearization.push_back(SE3::Exp(twist));
  }
  const int n = 6 * kPoses;
  Eigen::MatrixXd factor(n - 6, n);
  for (int i = 0; i < factor.rows(); ++i) {
    for (int j = 0; j < n; ++j) factor(i, j) = normal(*rng);
  }
  prior.information = factor.transpose() * factor;
  prior.gradient = factor.transpose() * Eigen::VectorXd::Random(n - 6);
  return prior;
}

std::vector<std::array<double, 7>> Perturbed(const std::vector<SE3>& poses, double size,
                                             std::mt19937* rng, Eigen::VectorXd* deltas) {
  std::normal_distribution<double> normal;
  std::vector<std::array<double, 7>> parameters(poses.size());
  deltas->resize(6 * poses.size());
  for (size_t k = 0; k < poses.size(); ++k) {
    Vector6d twist;
    for (int i = 0; i < 6; ++i) twist[i] = size * normal(*rng);
    deltas->segment<6>(6 * k) = twist;
    PoseToParameters(SE3::Exp(twist) * poses[k], parameters[k].data());
  }
  return parameters;
}

TEST(PosePriorResidualTest, SquaredNormIsTheQuadraticEnergyUpToAConstant) {
  std::mt19937 rng(7);
  const Prior prior = RandomPrior(&rng);
  const PosePriorResidual residual(prior.linearization, prior.information, prior.gradient);
  EXPECT_EQ(residual.num_residuals(), 6 * kPoses - 6);  // the gauge directions are dropped

  auto half_squared_norm = [&](const std::vector<std::array<double, 7>>& parameters) {
    std::vector<const double*> blocks;
    for (const auto& p : parameters) blocks.push_back(p.data());
    Eigen::VectorXd r(residual.num_residuals());
    EXPECT_TRUE(residual.Evaluate(blocks.data(), r.data(), nullptr));
    return 0.5 * r.squaredNorm();
  };
  Eigen::VectorXd zero;
  const double at_linearization =
      half_squared_norm(Perturbed(prior.linearization, 0.0, &rng, &zero));
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd deltas;
    const double energy = half_squared_norm(Perturbed(prior.linearization, 0.2, &rng, &deltas));
    const double expected =
        0.5 * deltas.dot(prior.information * deltas) + prior.gradient.dot(deltas);
    EXPECT_NEAR(energy - at_linearization, expected, 1e-9 * (1.0 + std::abs(expected)));
  }
}

TEST(PosePriorResidualTest, GradientCheckerAwayFromTheLinearizationPoint) {
  std::mt19937 rng(8);
  const Prior prior = RandomPrior(&rng);
  const PosePriorResidual residual(prior.linearization, prior.information, prior.gradient);
  Eigen::VectorXd deltas;
  const auto parameters = Perturbed(prior.linearization, 0.3, &rng, &deltas);
  std::vector<const double*> blocks;
  for (const auto& p : parameters) blocks.push_back(p.data());
  const SE3Manifold se3;
  const std::vector<const ceres::Manifold*> manifolds(kPoses, &se3);
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-5;
  const ceres::GradientChecker checker(&residual, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-7, &results)) << results.error_log;
  EXPECT_LT(results.maximum_relative_error, 1e-7);
}

TEST(PosePriorResidualTest, RejectsMalformedInput) {
  std::mt19937 rng(9);
  const Prior prior = RandomPrior(&rng);
  EXPECT_THROW(PosePriorResidual({}, prior.information, prior.gradient), std::invalid_argument);
  EXPECT_THROW(
      PosePriorResidual(prior.linearization, prior.information.topLeftCorner(6, 6), prior.gradient),
      std::invalid_argument);
  EXPECT_THROW(PosePriorResidual(prior.linearization, Eigen::MatrixXd::Zero(18, 18),
                                 Eigen::VectorXd::Zero(18)),
               std::invalid_argument);
  Eigen::MatrixXd not_finite = prior.information;
  not_finite(0, 0) = std::nan("");
  EXPECT_THROW(PosePriorResidual(prior.linearization, not_finite, prior.gradient),
               std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
