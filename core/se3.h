// SO(3) and SE(3) on Eigen. Twists are ordered (t; w) as in the seed paper (Yang & Scherer,
// ICRA 2017, Sec. IV): xi = (v, w) in R^6, v the translational and w the rotational part.
// Exp maps a twist to a rigid transform with the closed-form SE(3) exponential
// (Barfoot, "State Estimation for Robotics", eq. 7.85):
//   R = exp([w]x),  t = V(w) v,  V = I + (1 - cos a)/a^2 [w]x + (a - sin a)/a^3 [w]x^2, a = |w|.
#ifndef PLDVO_CORE_SE3_H_
#define PLDVO_CORE_SE3_H_

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pldvo {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// [w]x, the skew-symmetric matrix with Hat(w) * p = w.cross(p).
Eigen::Matrix3d Hat(const Eigen::Vector3d& w);
// Inverse of Hat for a skew-symmetric matrix.
Eigen::Vector3d Vee(const Eigen::Matrix3d& w_hat);

// Rodrigues' formula; exact to machine precision for any angle, Taylor series near 0.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w);
// Rotation vector of R with |w| in [0, pi]; stable near 0 and near pi (through the quaternion).
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation);
// Left Jacobian of SO(3), V(w) above; its inverse.
Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& w);
Eigen::Matrix3d InverseLeftJacobianSO3(const Eigen::Vector3d& w);
// Inverse of the left Jacobian of SE(3) for a twist (v; w) (Barfoot, eqs. 7.86 and 7.95):
//   J^-1 = [Jw^-1, -Jw^-1 Q(v, w) Jw^-1; 0, Jw^-1],
// so that Log(Exp(e) Exp(xi)) = xi + J^-1(xi) e + O(|e|^2).
Matrix6d InverseLeftJacobianSE3(const Vector6d& twist);

// A rigid transform b_from_a: p_b = R p_a + t. Rotation stored as a unit quaternion.
class SE3 {
 public:
  SE3() : rotation_(Eigen::Quaterniond::Identity()), translation_(Eigen::Vector3d::Zero()) {}
  SE3(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : rotation_(rotation.normalized()), translation_(translation) {}
  SE3(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
      : rotation_(Eigen::Quaterniond(rotation).normalized()), translation_(translation) {}

  // Exp of a twist (t; w).
  static SE3 Exp(const Vector6d& twist);
  // Log, the inverse of Exp: a twist (t; w) with |w| in [0, pi].
  Vector6d Log() const;
  // Adjoint for twists ordered (t; w): Ad = [R, [t]x R; 0, R], so that
  // T Exp(xi) T^-1 = Exp(Ad xi).
  Matrix6d Adjoint() const;

  SE3 Inverse() const;
  SE3 operator*(const SE3& other) const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const;

  const Eigen::Quaterniond& rotation() const { return rotation_; }
  Eigen::Matrix3d rotation_matrix() const { return rotation_.toRotationMatrix(); }
  const Eigen::Vector3d& translation() const { return translation_; }
  Eigen::Matrix4d matrix() const;

 private:
  Eigen::Quaterniond rotation_;
  Eigen::Vector3d translation_;
};

}  // namespace pldvo

#endif  // PLDVO_CORE_SE3_H_
