#include "residuals/line_observation_residual.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "residuals/robustify.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

[[noreturn]] void ThrowInvalid(int line, const std::string& what) {
  std::ostringstream message;
  message << __FILE__ << ":" << line << ": LineObservationResidual: " << what;
  throw std::invalid_argument(message.str());
}

// Relative threshold below which the projected line is undefined (line through the centre).
constexpr double kDegenerateRatio = 1e-12;

}  // namespace

LineObservationResidual::LineObservationResidual(const PinholeCamera& camera,
                                                 std::vector<LineObservationPixel> pixels,
                                                 const ceres::LossFunction* loss)
    : camera_(camera), pixels_(std::move(pixels)), loss_(loss) {
  if (pixels_.empty()) ThrowInvalid(__LINE__, "empty batch");
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) ThrowInvalid(__LINE__, "camera: " + camera_error);
  rays_.reserve(pixels_.size());
  for (size_t i = 0; i < pixels_.size(); ++i) {
    const LineObservationPixel& p = pixels_[i];
    if (!p.pixel.allFinite() || !(p.sqrt_info >= 0.0) || !std::isfinite(p.sqrt_info)) {
      ThrowInvalid(__LINE__, "pixel " + std::to_string(i) +
                                 " has a non-finite coordinate or a negative sqrt_info");
    }
    rays_.push_back(camera_.Unproject(p.pixel));
  }
  set_num_residuals(static_cast<int>(pixels_.size()));
  mutable_parameter_block_sizes()->push_back(kPoseAmbientSize);
  mutable_parameter_block_sizes()->push_back(kLineAmbientSize);
}

bool LineObservationResidual::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  const SE3 cam_from_world = PoseFromParameters(parameters[0]);
  const Eigen::Matrix3d rotation = cam_from_world.rotation_matrix();
  const Eigen::Map<const Eigen::Vector3d> o(parameters[1]);
  const Eigen::Map<const Eigen::Vector3d> d(parameters[1] + 3);
  const Eigen::Vector3d d_c = rotation * d;
  const Eigen::Vector3d o_c = rotation * o + cam_from_world.translation();
  const Eigen::Vector3d n = o_c.cross(d_c);
  const double inv_fx = 1.0 / camera_.fx;
  const double inv_fy = 1.0 / camera_.fy;
  const double den_sq = n.x() * n.x() * inv_fx * inv_fx + n.y() * n.y() * inv_fy * inv_fy;
  const double den = std::sqrt(den_sq);
  if (!(den > kDegenerateRatio * n.norm() * std::max(inv_fx, inv_fy)) || !(den > 0.0)) {
    return false;
  }
  const double inv_den = 1.0 / den;

  const bool want_pose = jacobians != nullptr && jacobians[0] != nullptr;
  const bool want_line = jacobians != nullptr && jacobians[1] != nullptr;
  // dn/d(pose tangent) (3x6) and dn/d(line ambient) (3x6), shared by every row.
  Eigen::Matrix<double, 3, 6> dn_dpose;
  Eigen::Matrix<double, 3, 6> dn_dline;
  if (want_pose) {
    dn_dpose.leftCols<3>() = -Hat(d_c);
    dn_dpose.rightCols<3>() = -Hat(n);
  }
  if (want_line) {
    dn_dline.leftCols<3>() = -Hat(d_c) * rotation;
    dn_dline.rightCols<3>() = Hat(o_c) * rotation;
  }
  const Eigen::Vector3d dden(n.x() * inv_fx * inv_fx, n.y() * inv_fy * inv_fy, 0.0);
  const MinusJacobianMatrix minus_jacobian =
      want_pose ? PoseMinusJacobian(parameters[0]) : MinusJacobianMatrix::Zero();

  for (size_t j = 0; j < pixels_.size(); ++j) {
    const Eigen::Vector3d& m = rays_[j];
    const double dot = n.dot(m);
    const double distance = dot * inv_den;
    double scale;
    residuals[j] = RobustifyRow(loss_, pixels_[j].sqrt_info * distance, &scale);
    if (!want_pose && !want_line) continue;
    const double w = pixels_[j].sqrt_info * scale;
    // dr/dn (1x3).
    const Eigen::Matrix<double, 1, 3> dr_dn =
        w * (m * inv_den - dden * (dot * inv_den * inv_den * inv_den)).transpose();
    if (want_pose) {
      double tangent[6];
      Eigen::Map<Eigen::Matrix<double, 1, 6> > j_tangent(tangent);
      j_tangent.noalias() = dr_dn * dn_dpose;
      LiftTangentJacobian(minus_jacobian, tangent, 1, jacobians[0] + 7 * j);
    }
    if (want_line) {
      Eigen::Map<Eigen::Matrix<double, 1, 6> > j_line(jacobians[1] + 6 * j);
      j_line.noalias() = dr_dn * dn_dline;
    }
  }
  return true;
}

bool ProjectLine(const PinholeCamera& camera, const SE3& cam_from_world,
                 const Eigen::Vector3d& point_in_world, const Eigen::Vector3d& direction_in_world,
                 Eigen::Vector3d* line_in_image) {
  const Eigen::Vector3d o_c = cam_from_world * point_in_world;
  const Eigen::Vector3d d_c = cam_from_world.rotation() * direction_in_world;
  const Eigen::Vector3d n = o_c.cross(d_c);
  // l = K^-T n.
  const Eigen::Vector3d l(n.x() / camera.fx, n.y() / camera.fy,
                          n.z() - camera.cx * n.x() / camera.fx - camera.cy * n.y() / camera.fy);
  const double norm = l.head<2>().norm();
  if (!(norm > kDegenerateRatio * n.norm() / std::min(camera.fx, camera.fy)) || !(norm > 0.0)) {
    return false;
  }
  *line_in_image = l / norm;
  return true;
}

}  // namespace pldvo
