#include "residuals/host_target_point_to_line_residual.h"

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
  message << __FILE__ << ":" << line << ": HostTargetPointToLineResidual: " << what;
  throw std::invalid_argument(message.str());
}

}  // namespace

HostTargetPointToLineResidual::HostTargetPointToLineResidual(const PinholeCamera& camera,
                                                             const Eigen::Vector2d& pixel_in_host,
                                                             const Eigen::Vector3d& line_in_target,
                                                             double sqrt_info,
                                                             const ceres::LossFunction* loss)
    : camera_(camera),
      ray_in_host_(camera.Unproject(pixel_in_host)),
      line_in_target_(line_in_target),
      sqrt_info_(sqrt_info),
      loss_(loss) {
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) ThrowInvalid(__LINE__, "camera: " + camera_error);
  if (!pixel_in_host.allFinite() || !line_in_target.allFinite()) {
    ThrowInvalid(__LINE__, "non-finite pixel or line");
  }
  if (std::abs(line_in_target.head<2>().squaredNorm() - 1.0) > 1e-6) {
    ThrowInvalid(__LINE__, "line not normalised (a^2 + b^2 != 1)");
  }
  if (!(sqrt_info >= 0.0) || !std::isfinite(sqrt_info)) {
    ThrowInvalid(__LINE__, "negative or non-finite sqrt_info");
  }
}

bool HostTargetPointToLineResidual::Evaluate(double const* const* parameters, double* residuals,
                                             double** jacobians) const {
  const SE3 host_from_world = PoseFromParameters(parameters[0]);
  const SE3 target_from_world = PoseFromParameters(parameters[1]);
  const SE3 target_from_host = target_from_world * host_from_world.Inverse();
  const Eigen::Matrix3d rotation = target_from_host.rotation_matrix();
  const Eigen::Vector3d& translation = target_from_host.translation();
  const double idepth = parameters[2][0];
  const Eigen::Vector3d q = rotation * ray_in_host_ + idepth * translation;
  auto want = [&](int block) { return jacobians != nullptr && jacobians[block] != nullptr; };
  bool valid = q.z() > 0.0;
  double u = 0.0, v = 0.0;
  if (valid) {
    u = camera_.fx * q.x() / q.z() + camera_.cx;
    v = camera_.fy * q.y() / q.z() + camera_.cy;
    valid = u >= 0.0 && v >= 0.0 && u <= camera_.width - 1 && v <= camera_.height - 1;
  }
  if (!valid) {
    residuals[0] = 0.0;
    if (want(0)) std::fill_n(jacobians[0], kPoseAmbientSize, 0.0);
    if (want(1)) std::fill_n(jacobians[1], kPoseAmbientSize, 0.0);
    if (want(2)) jacobians[2][0] = 0.0;
    return true;
  }
  double scale = 1.0;
  residuals[0] = RobustifyRow(
      loss_, sqrt_info_ * (line_in_target_.x() * u + line_in_target_.y() * v + line_in_target_.z()),
      &scale);
  if (!want(0) && !want(1) && !want(2)) return true;
  // c = dg/dq = w (a, b) dpi/dq.
  const double w = sqrt_info_ * scale;
  const double inv_z = 1.0 / q.z();
  const double afx = w * line_in_target_.x() * camera_.fx * inv_z;
  const double bfy = w * line_in_target_.y() * camera_.fy * inv_z;
  const Eigen::Vector3d c(afx, bfy, -(afx * q.x() + bfy * q.y()) * inv_z);
  double tangent[kPoseTangentSize];
  Eigen::Map<Eigen::Matrix<double, 6, 1>> row(tangent);
  if (want(1)) {
    row.head<3>() = idepth * c;
    row.tail<3>() = q.cross(c);
    LiftTangentJacobian(PoseMinusJacobian(parameters[1]), tangent, 1, jacobians[1]);
  }
  if (want(0)) {
    const Eigen::Vector3d c_host = rotation.transpose() * c;
    row.head<3>() = -idepth * c_host;
    row.tail<3>() = c_host.cross(ray_in_host_);
    LiftTangentJacobian(PoseMinusJacobian(parameters[0]), tangent, 1, jacobians[0]);
  }
  if (want(2)) jacobians[2][0] = c.dot(translation);
  return true;
}

}  // namespace pldvo
