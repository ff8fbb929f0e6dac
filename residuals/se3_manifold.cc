#include "residuals/se3_manifold.h"

#include <cmath>

namespace pldvo {
namespace {
// Below this angle the closed forms use their Taylor series.
constexpr double kSmallAngle = 1e-5;
}  // namespace

SE3 PoseFromParameters(const double* parameters) {
  const Eigen::Quaterniond rotation(parameters[6], parameters[3], parameters[4], parameters[5]);
  return SE3(rotation, Eigen::Vector3d(parameters[0], parameters[1], parameters[2]));
}

void PoseToParameters(const SE3& b_from_a, double* parameters) {
  Eigen::Map<Eigen::Vector3d> translation(parameters);
  translation = b_from_a.translation();
  Eigen::Quaterniond rotation = b_from_a.rotation();
  if (rotation.w() < 0.0) rotation.coeffs() = -rotation.coeffs();
  Eigen::Map<Eigen::Vector4d> coeffs(parameters + 3);
  coeffs = rotation.coeffs();  // x y z w
}

// Plus(x, delta) = Exp(delta) * x with delta = (v; w). At delta = 0:
//   t' = exp(w) t + V(w) v  ->  dt'/dv = I, dt'/dw = -[t]x;
//   q' = (w/2; 1) (x) q     ->  dq'_vec/dw = (q_w I - [q_vec]x) / 2, dq'_w/dw = -q_vec^T / 2.
PlusJacobianMatrix PosePlusJacobian(const double* x) {
  const Eigen::Map<const Eigen::Vector3d> t(x);
  // Plus normalises its result, so its derivative is taken at the normalised quaternion.
  const Eigen::Vector4d q = Eigen::Map<const Eigen::Vector4d>(x + 3).normalized();
  const Eigen::Vector3d q_vec = q.head<3>();
  const double q_w = q[3];
  PlusJacobianMatrix jacobian = PlusJacobianMatrix::Zero();
  jacobian.block<3, 3>(0, 0).setIdentity();
  jacobian.block<3, 3>(0, 3) = -Hat(t);
  jacobian.block<3, 3>(3, 3) = 0.5 * (q_w * Eigen::Matrix3d::Identity() - Hat(q_vec));
  jacobian.block<1, 3>(6, 3) = -0.5 * q_vec.transpose();
  return jacobian;
}

// Minus(y, x) = Log(y x^-1). At y = x, with y x^-1 = (exp(dw), t_y - exp(dw) t_x):
//   dw = 2 vec(q_y (x) q_x^*)  ->  dw/dq_y,vec = 2 (q_w I + [q_vec]x), dw/dq_y,w = -2 q_vec;
//   dv = t_y - t_x - dw x t_x  ->  dv/dt_y = I, dv/dq_y = [t_x]x dw/dq_y.
// MinusJacobian * PlusJacobian = I_6 for a unit quaternion.
MinusJacobianMatrix PoseMinusJacobian(const double* x) {
  const Eigen::Map<const Eigen::Vector3d> t(x);
  const Eigen::Map<const Eigen::Vector3d> q_vec(x + 3);
  const double q_w = x[6];
  // Evaluated at q / |q| (like PlusJacobian) so that MinusJacobian * PlusJacobian = I_6 holds
  // exactly also when the stored quaternion has drifted slightly from unit norm.
  const double inv_norm = 1.0 / std::sqrt(q_vec.squaredNorm() + q_w * q_w);
  Eigen::Matrix<double, 3, 4> dw_dq;
  dw_dq.leftCols<3>() = 2.0 * inv_norm * (q_w * Eigen::Matrix3d::Identity() + Hat(q_vec));
  dw_dq.col(3) = -2.0 * inv_norm * q_vec;
  MinusJacobianMatrix jacobian = MinusJacobianMatrix::Zero();
  jacobian.block<3, 3>(0, 0).setIdentity();
  jacobian.block<3, 4>(0, 3) = Hat(t) * dw_dq;
  jacobian.block<3, 4>(3, 3) = dw_dq;
  return jacobian;
}

bool SE3Manifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Vector3d> t(x);
  const Eigen::Quaterniond q(x[6], x[3], x[4], x[5]);
  const Eigen::Map<const Eigen::Vector3d> v(delta);
  const Eigen::Map<const Eigen::Vector3d> w(delta + 3);
  // Exp(delta) = (exp([w]x), V(w) v); its quaternion (cos(a/2), sin(a/2) w/a) has a
  // non-negative scalar part for a <= pi, so the product keeps the sign of x's quaternion.
  const double angle = w.norm();
  Eigen::Quaterniond q_delta;
  q_delta.w() = std::cos(0.5 * angle);
  q_delta.vec() =
      (angle < kSmallAngle ? 0.5 - angle * angle / 48.0 : std::sin(0.5 * angle) / angle) * w;
  const Eigen::Quaterniond q_result = (q_delta * q).normalized();
  Eigen::Map<Eigen::Vector3d> t_result(x_plus_delta);
  t_result = q_delta * t + LeftJacobianSO3(w) * v;
  Eigen::Map<Eigen::Vector4d> q_result_coeffs(x_plus_delta + 3);
  q_result_coeffs = q_result.coeffs();
  return true;
}

bool SE3Manifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<PlusJacobianMatrix> jacobian_map(jacobian);
  jacobian_map = PosePlusJacobian(x);
  return true;
}

bool SE3Manifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Quaterniond q_x = Eigen::Quaterniond(x[6], x[3], x[4], x[5]).normalized();
  const Eigen::Quaterniond q_y = Eigen::Quaterniond(y[6], y[3], y[4], y[5]).normalized();
  const Eigen::Quaterniond q_delta = q_y * q_x.conjugate();
  // Rotation vector of q_delta with the half angle atan2(|vec|, w) in [0, pi]: the rotation
  // angle is in [0, 2 pi), so that Plus(x, Minus(y, x)) reproduces y's quaternion sign too.
  const double vec_norm = q_delta.vec().norm();
  const Eigen::Vector3d w =
      (vec_norm < kSmallAngle && q_delta.w() > 0.0
           ? 2.0 / q_delta.w() * (1.0 - vec_norm * vec_norm / (3.0 * q_delta.w() * q_delta.w()))
           : 2.0 * std::atan2(vec_norm, q_delta.w()) / vec_norm) *
      q_delta.vec();
  const Eigen::Vector3d t_delta =
      Eigen::Map<const Eigen::Vector3d>(y) - q_delta * Eigen::Map<const Eigen::Vector3d>(x);
  Eigen::Map<Eigen::Vector3d> v_out(y_minus_x);
  v_out = InverseLeftJacobianSO3(w) * t_delta;
  Eigen::Map<Eigen::Vector3d> w_out(y_minus_x + 3);
  w_out = w;
  return true;
}

bool SE3Manifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<MinusJacobianMatrix> jacobian_map(jacobian);
  jacobian_map = PoseMinusJacobian(x);
  return true;
}

}  // namespace pldvo
