#include "core/se3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/random_draws.h"

namespace pldvo {
namespace {

// Central differences of a smooth map in double precision: step 1e-6 leaves an error near
// 1e-10 (truncation h^2 plus rounding eps/h), so 1e-8 is a safe tolerance.
constexpr double kStep = 1e-6;
constexpr double kNumericTolerance = 1e-8;

Eigen::Vector3d RandomAxis(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return DrawVector3(normal, rng).normalized();
}

TEST(SO3, ExpMatchesAngleAxisAcrossAngles) {
  std::mt19937 rng(1);
  for (double angle : {0.0, 1e-9, 1e-6, 1e-3, 0.5, 2.0, M_PI - 1e-6, M_PI}) {
    const Eigen::Vector3d axis = RandomAxis(rng);
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((ExpSO3(angle * axis) - expected).norm(), 1e-12) << "angle " << angle;
  }
}

TEST(SO3, LogInvertsExpNearZeroAndNearPi) {
  std::mt19937 rng(2);
  for (double angle : {0.0, 1e-12, 1e-7, 1e-3, 1.0, 3.0, M_PI - 1e-4, M_PI - 1e-9}) {
    const Eigen::Vector3d w = angle * RandomAxis(rng);
    const Eigen::Vector3d log = LogSO3(Eigen::AngleAxisd(angle, w.normalized()).toRotationMatrix());
    // Near pi the rotation matrix itself only holds the angle to about sqrt(eps) ~ 1e-8.
    const double tolerance = angle > 3.0 ? 1e-7 : 1e-12;
    if (angle == 0.0) {
      EXPECT_LT(log.norm(), 1e-15);
    } else {
      EXPECT_LT((log - w).norm(), tolerance) << "angle " << angle;
    }
  }
  // At exactly pi the sign of the axis is ambiguous; the rotation must still be reproduced.
  const Eigen::Vector3d axis = RandomAxis(rng);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(M_PI, axis).toRotationMatrix();
  const Eigen::Vector3d log = LogSO3(rotation);
  EXPECT_NEAR(log.norm(), M_PI, 1e-7);
  EXPECT_LT((ExpSO3(log) - rotation).norm(), 1e-7);
}

TEST(SO3, HatVeeAndCrossProduct) {
  const Eigen::Vector3d w(0.3, -1.2, 2.0), p(-0.7, 0.1, 0.4);
  EXPECT_LT((Hat(w) * p - w.cross(p)).norm(), 1e-15);
  EXPECT_LT((Vee(Hat(w)) - w).norm(), 1e-15);
}

TEST(SO3, LeftJacobianMatchesNumericDerivativeOfExp) {
  // exp(w + dw) = exp(J_l(w) dw) exp(w) to first order.
  std::mt19937 rng(3);
  for (double angle : {1e-7, 0.1, 1.5, 3.0}) {
    const Eigen::Vector3d w = angle * RandomAxis(rng);
    Eigen::Matrix3d numeric;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d dw = Eigen::Vector3d::Zero();
      dw[k] = kStep;
      const Eigen::Matrix3d plus = ExpSO3(w + dw) * ExpSO3(w).transpose();
      const Eigen::Matrix3d minus = ExpSO3(w - dw) * ExpSO3(w).transpose();
      numeric.col(k) = (LogSO3(plus) - LogSO3(minus)) / (2.0 * kStep);
    }
    EXPECT_LT((numeric - LeftJacobianSO3(w)).norm(), kNumericTolerance) << "angle " << angle;
    EXPECT_LT((LeftJacobianSO3(w) * InverseLeftJacobianSO3(w) - Eigen::Matrix3d::Identity()).norm(),
              1e-12);
  }
}

TEST(SE3, InverseLeftJacobianMatchesNumericDerivativeOfLog) {
  // Log(Exp(e) Exp(xi)) = xi + J^-1(xi) e to first order; angles on both sides of the switch to
  // the Taylor series (0.05 rad).
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  for (double angle : {0.0, 1e-7, 0.01, 0.049, 0.051, 0.5, 2.5}) {
    Vector6d xi;
    xi.head<3>() = 0.3 * DrawVector3(normal, rng);
    xi.tail<3>() = angle * RandomAxis(rng);
    const SE3 base = SE3::Exp(xi);
    Matrix6d numeric;
    for (int k = 0; k < 6; ++k) {
      Vector6d e = Vector6d::Zero();
      e[k] = kStep;
      numeric.col(k) = ((SE3::Exp(e) * base).Log() - (SE3::Exp(-e) * base).Log()) / (2.0 * kStep);
    }
    EXPECT_LT((numeric - InverseLeftJacobianSE3(xi)).norm(), kNumericTolerance)
        << "angle " << angle;
  }
}

TEST(SE3, ExpLogRoundTrip) {
  std::mt19937 rng(4);
  std::normal_distribution<double> normal;
  for (double angle : {0.0, 1e-8, 0.2, 2.5, M_PI - 1e-5}) {
    Vector6d twist;
    twist.head<3>() << normal(rng), normal(rng), normal(rng);
    twist.tail<3>() = angle * RandomAxis(rng);
    const Vector6d log = SE3::Exp(twist).Log();
    EXPECT_LT((log - twist).norm(), 1e-9) << "angle " << angle;
  }
}

TEST(SE3, ExpIsTheMatrixExponential) {
  // Exp(xi) equals the 4x4 matrix exponential of [[w]x, v; 0, 0], summed as a series.
  Vector6d twist;
  twist << 0.4, -0.2, 1.1, 0.3, 0.5, -0.9;
  Eigen::Matrix4d generator = Eigen::Matrix4d::Zero();
  generator.topLeftCorner<3, 3>() = Hat(twist.tail<3>());
  generator.topRightCorner<3, 1>() = twist.head<3>();
  Eigen::Matrix4d series = Eigen::Matrix4d::Identity(), term = Eigen::Matrix4d::Identity();
  for (int k = 1; k < 40; ++k) {
    term = term * generator / k;
    series += term;
  }
  EXPECT_LT((SE3::Exp(twist).matrix() - series).norm(), 1e-12);
}

TEST(SE3, AdjointConjugatesTwists) {
  Vector6d a, b;
  a << 0.2, -1.0, 0.5, 0.7, -0.4, 0.1;
  b << -0.3, 0.2, 0.9, 0.05, 0.3, -0.2;
  const SE3 transform = SE3::Exp(a);
  const SE3 lhs = transform * SE3::Exp(b) * transform.Inverse();
  const SE3 rhs = SE3::Exp(transform.Adjoint() * b);
  EXPECT_LT((lhs.matrix() - rhs.matrix()).norm(), 1e-12);
}

TEST(SE3, ComposeInverseAndActOnPoints) {
  Vector6d a;
  a << 1.0, 2.0, 3.0, 0.1, 0.2, 0.3;
  const SE3 b_from_a = SE3::Exp(a);
  const Eigen::Vector3d point_in_a(0.5, -0.25, 2.0);
  const Eigen::Vector3d point_in_b = b_from_a * point_in_a;
  EXPECT_LT((b_from_a.Inverse() * point_in_b - point_in_a).norm(), 1e-14);
  EXPECT_LT(((b_from_a * b_from_a.Inverse()).matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-14);
  EXPECT_LT((b_from_a.matrix() * point_in_a.homogeneous() - point_in_b.homogeneous()).norm(),
            1e-14);
}

}  // namespace
}  // namespace pldvo
