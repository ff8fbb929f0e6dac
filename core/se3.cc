#include "core/se3.h"

#include <cmath>

namespace pldvo {
namespace {
// Below this angle the closed forms lose precision; their Taylor series are used instead.
constexpr double kSmallAngle = 1e-5;
}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d w_hat;
  w_hat << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return w_hat;
}

Eigen::Vector3d Vee(const Eigen::Matrix3d& w_hat) {
  return Eigen::Vector3d(w_hat(2, 1), w_hat(0, 2), w_hat(1, 0));
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  const Eigen::Matrix3d w_hat = Hat(w);
  if (angle < kSmallAngle) {
    return Eigen::Matrix3d::Identity() + w_hat + 0.5 * w_hat * w_hat;
  }
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d v = q.vec();
  const double n = v.norm();
  // angle = 2 atan2(n, w); w = angle * v / n, with the series 2/w (1 - n^2 / (3 w^2)) near 0.
  if (n < kSmallAngle) {
    return (2.0 / q.w()) * (1.0 - n * n / (3.0 * q.w() * q.w())) * v;
  }
  return (2.0 * std::atan2(n, q.w()) / n) * v;
}

Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  const Eigen::Matrix3d w_hat = Hat(w);
  if (angle < kSmallAngle) {
    return Eigen::Matrix3d::Identity() + 0.5 * w_hat + w_hat * w_hat / 6.0;
  }
  const double a2 = angle * angle;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(angle)) / a2 * w_hat +
         (angle - std::sin(angle)) / (a2 * angle) * w_hat * w_hat;
}

Eigen::Matrix3d InverseLeftJacobianSO3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  const Eigen::Matrix3d w_hat = Hat(w);
  if (angle < kSmallAngle) {
    return Eigen::Matrix3d::Identity() - 0.5 * w_hat + w_hat * w_hat / 12.0;
  }
  const double half = 0.5 * angle;
  const double coefficient = (1.0 - half * std::cos(half) / std::sin(half)) / (angle * angle);
  return Eigen::Matrix3d::Identity() - 0.5 * w_hat + coefficient * w_hat * w_hat;
}

Matrix6d InverseLeftJacobianSE3(const Vector6d& twist) {
  const Eigen::Matrix3d v = Hat(twist.head<3>());
  const Eigen::Matrix3d w = Hat(twist.tail<3>());
  const double a = twist.tail<3>().norm();
  const double a2 = a * a;
  // Q's coefficients; their closed forms cancel catastrophically for small angles (the second
  // one as 1/a^4), so their Taylor series are used below 0.05 rad (truncation below 1e-13).
  double c1, c2, c3;
  if (a < 0.05) {
    c1 = 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0;
    c2 = 1.0 / 24.0 - a2 / 720.0 + a2 * a2 / 40320.0;
    c3 = 1.0 / 120.0 - a2 / 2520.0 + a2 * a2 / 120960.0;
  } else {
    const double s = std::sin(a);
    const double c = std::cos(a);
    c1 = (a - s) / (a2 * a);
    c2 = (a2 + 2.0 * c - 2.0) / (2.0 * a2 * a2);
    c3 = (2.0 * a - 3.0 * s + a * c) / (2.0 * a2 * a2 * a);
  }
  const Eigen::Matrix3d wv = w * v;
  const Eigen::Matrix3d vw = v * w;
  const Eigen::Matrix3d wvw = wv * w;
  const Eigen::Matrix3d q = 0.5 * v + c1 * (wv + vw + wvw) + c2 * (w * wv + vw * w - 3.0 * wvw) +
                            c3 * (wvw * w + w * wvw);
  const Eigen::Matrix3d inverse_w = InverseLeftJacobianSO3(twist.tail<3>());
  Matrix6d inverse = Matrix6d::Zero();
  inverse.topLeftCorner<3, 3>() = inverse_w;
  inverse.bottomRightCorner<3, 3>() = inverse_w;
  inverse.topRightCorner<3, 3>() = -inverse_w * q * inverse_w;
  return inverse;
}

SE3 SE3::Exp(const Vector6d& twist) {
  const Eigen::Vector3d v = twist.head<3>();
  const Eigen::Vector3d w = twist.tail<3>();
  return SE3(ExpSO3(w), LeftJacobianSO3(w) * v);
}

Vector6d SE3::Log() const {
  const Eigen::Vector3d w = LogSO3(rotation_matrix());
  Vector6d twist;
  twist.head<3>() = InverseLeftJacobianSO3(w) * translation_;
  twist.tail<3>() = w;
  return twist;
}

Matrix6d SE3::Adjoint() const {
  const Eigen::Matrix3d rotation = rotation_matrix();
  Matrix6d adjoint = Matrix6d::Zero();
  adjoint.topLeftCorner<3, 3>() = rotation;
  adjoint.topRightCorner<3, 3>() = Hat(translation_) * rotation;
  adjoint.bottomRightCorner<3, 3>() = rotation;
  return adjoint;
}

SE3 SE3::Inverse() const {
  const Eigen::Quaterniond inverse = rotation_.conjugate();
  return SE3(inverse, -(inverse * translation_));
}

SE3 SE3::operator*(const SE3& other) const {
  return SE3(rotation_ * other.rotation_, rotation_ * other.translation_ + translation_);
}

Eigen::Vector3d SE3::operator*(const Eigen::Vector3d& point) const {
  return rotation_ * point + translation_;
}

Eigen::Matrix4d SE3::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotation_matrix();
  m.topRightCorner<3, 1>() = translation_;
  return m;
}

}  // namespace pldvo
