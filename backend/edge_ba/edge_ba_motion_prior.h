// Motion prior of windowed edge bundle adjustment (docs/edge_ba.md, "Motion prior"): the relative
// pose between two consecutive window keyframes as tracking measured it, so that BA does not
// discard what the dense frame-to-keyframe tracking knows about the poses.
//
//   P_est = cam_a_from_world * (cam_b_from_world)^-1        (a_from_b, a = previous keyframe)
//   E     = P_meas^-1 * P_est = (dR, dt)
//   r     = (dt / sigma_t; 2 vec(dq) / sigma_r)             (dq = quaternion of dR, w >= 0)
//
// 2 vec(dq) is the rotation vector of dR to first order. sigma_t is in world units (the caller
// makes it scale-free, EdgeBAOptions::motion_prior_translation_ratio times |t_meas|), sigma_r in
// radians. Parameter blocks: [0] cam_a_from_world, [1] cam_b_from_world, double[7] each
// ([t, q], SE3Manifold); Jacobians by automatic differentiation.
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_MOTION_PRIOR_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_MOTION_PRIOR_H_

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Geometry>

#include "core/se3.h"

namespace pldvo {

class EdgeBAMotionPrior {
 public:
  EdgeBAMotionPrior(const SE3& a_from_b, double sigma_t, double sigma_r)
      : b_from_a_meas_(a_from_b.Inverse()), sigma_t_(sigma_t), sigma_r_(sigma_r) {}

  // Throws nothing; sigma_t and sigma_r must be > 0 (the builder checks).
  static ceres::CostFunction* Create(const SE3& a_from_b, double sigma_t, double sigma_r) {
    return new ceres::AutoDiffCostFunction<EdgeBAMotionPrior, 6, 7, 7>(
        new EdgeBAMotionPrior(a_from_b, sigma_t, sigma_r));
  }

  template <typename T>
  bool operator()(const T* pose_a, const T* pose_b, T* residuals) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    using Quaternion = Eigen::Quaternion<T>;
    const Eigen::Map<const Vector3> t_a(pose_a), t_b(pose_b);
    const Quaternion q_a = Quaternion(pose_a[6], pose_a[3], pose_a[4], pose_a[5]).normalized();
    const Quaternion q_b = Quaternion(pose_b[6], pose_b[3], pose_b[4], pose_b[5]).normalized();
    // a_from_b = a_from_world * world_from_b.
    const Quaternion q_b_inv = q_b.conjugate();
    const Quaternion q_ab = q_a * q_b_inv;
    const Vector3 t_ab = t_a - q_ab * t_b;
    // E = b_from_a_meas * a_from_b.
    const Quaternion q_m = b_from_a_meas_.rotation().cast<T>();
    const Vector3 t_m = b_from_a_meas_.translation().cast<T>();
    Quaternion q_e = q_m * q_ab;
    const Vector3 t_e = q_m * t_ab + t_m;
    if (q_e.w() < T(0)) q_e.coeffs() = -q_e.coeffs();
    for (int i = 0; i < 3; ++i) {
      residuals[i] = t_e[i] / T(sigma_t_);
      residuals[3 + i] = T(2.0) * q_e.vec()[i] / T(sigma_r_);
    }
    return true;
  }

 private:
  const SE3 b_from_a_meas_;
  const double sigma_t_;
  const double sigma_r_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_MOTION_PRIOR_H_
