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
