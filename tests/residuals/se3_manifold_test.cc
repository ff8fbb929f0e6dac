#include "residuals/se3_manifold.h"

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <random>

namespace pldvo {
namespace {

Eigen::VectorXd RandomPose(std::mt19937* rng, double rotation_scale) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vector6d twist;
  for (int i = 0; i < 6; ++i) twist[i] = normal(*rng);
  twist.tail<3>() *= rotation_scale;
  Eigen::VectorXd x(7);
  PoseToParameters(SE3::Exp(twist), x.data());
  return x;
}

// Manifold invariants (Ceres' own checks, including numeric Plus/Minus Jacobians by Ridders'
// method, accurate to ~1e-10 on these smooth functions; 1e-8 leaves margin for rounding).
TEST(SE3Manifold, InvariantsHold) {
  using namespace ceres;  // NOLINT: the macro names Ceres' matchers unqualified
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 0.3);
  const SE3Manifold manifold;
  for (int trial = 0; trial < 20; ++trial) {
    // Rotations up to about pi; both quaternion signs for y.
    const Eigen::VectorXd x = RandomPose(&rng, 0.8);
    Eigen::VectorXd y = RandomPose(&rng, 0.8);
    if (trial % 2 == 1) y.tail<4>() *= -1.0;
    Eigen::VectorXd delta(6);
    for (int i = 0; i < 6; ++i) delta[i] = normal(rng);
    constexpr double kTolerance = 1e-8;
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, kTolerance);
  }
}

TEST(SE3Manifold, PlusIsLeftMultiplicationByExp) {
  std::mt19937 rng(3);
  const Eigen::VectorXd x = RandomPose(&rng, 0.5);
  Vector6d delta;
  delta << 0.1, -0.2, 0.3, 0.05, 0.2, -0.1;
  Eigen::VectorXd x_plus_delta(7);
  ASSERT_TRUE(SE3Manifold().Plus(x.data(), delta.data(), x_plus_delta.data()));
  const SE3 expected = SE3::Exp(delta) * PoseFromParameters(x.data());
  const SE3 actual = PoseFromParameters(x_plus_delta.data());
  EXPECT_LT((actual.matrix() - expected.matrix()).norm(), 1e-12);
  // Minus is Log(y x^-1) for rotations below pi.
  Vector6d minus;
  ASSERT_TRUE(SE3Manifold().Minus(x_plus_delta.data(), x.data(), minus.data()));
  EXPECT_LT((minus - delta).norm(), 1e-12);
}

TEST(SE3Manifold, ParameterRoundTrip) {
  Vector6d twist;
  twist << 1.0, 2.0, -3.0, 0.4, -2.5, 0.7;
  const SE3 b_from_a = SE3::Exp(twist);
  double parameters[7];
  PoseToParameters(b_from_a, parameters);
  EXPECT_GE(parameters[6], 0.0);
  EXPECT_LT((PoseFromParameters(parameters).matrix() - b_from_a.matrix()).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(parameters[0], b_from_a.translation().x());
}

// The tangent convention the cost functions rely on: d(Exp(delta) p) / d delta = [I, -[p]x],
// checked by central differences (step 1e-6: truncation 1e-12, rounding 1e-10).
TEST(SE3Manifold, TangentConventionForPoints) {
  const Eigen::Vector3d point(0.4, -1.2, 3.0);
  Eigen::Matrix<double, 3, 6> expected;
  expected << Eigen::Matrix3d::Identity(), -Hat(point);
  constexpr double kStep = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    delta[k] = kStep;
    const Eigen::Vector3d numeric =
        (SE3::Exp(delta) * point - SE3::Exp(-delta) * point) / (2.0 * kStep);
    EXPECT_LT((numeric - expected.col(k)).norm(), 1e-8) << "column " << k;
  }
}

// The lifting J_ambient = J_tangent * MinusJacobian satisfies J_ambient * PlusJacobian =
// J_tangent exactly (up to rounding), also for a quaternion slightly off unit norm.
TEST(SE3Manifold, LiftingRecoversTangentJacobian) {
  std::mt19937 rng(11);
  Eigen::VectorXd x = RandomPose(&rng, 1.0);
  for (const double scale : {1.0, 1.0 + 1e-7}) {
    x.tail<4>() *= scale;
    Eigen::Matrix<double, 3, 6, Eigen::RowMajor> jacobian_tangent =
        Eigen::Matrix<double, 3, 6, Eigen::RowMajor>::Random();
    Eigen::Matrix<double, 3, 7, Eigen::RowMajor> jacobian_ambient;
    LiftTangentJacobian(PoseMinusJacobian(x.data()), jacobian_tangent.data(), 3,
                        jacobian_ambient.data());
    const Eigen::Matrix<double, 3, 6> recovered = jacobian_ambient * PosePlusJacobian(x.data());
    EXPECT_LT((recovered - jacobian_tangent).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace pldvo
