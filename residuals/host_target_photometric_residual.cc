#include "residuals/host_target_photometric_residual.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "residuals/robustify.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

// The sampling area of photometric_residual.h: [1, w - 2) x [1, h - 2).
constexpr double kSamplingBorder = 1.0;

[[noreturn]] void ThrowInvalid(int line, const std::string& what) {
  std::ostringstream message;
  message << __FILE__ << ":" << line << ": HostTargetPhotometricResidual: " << what;
  throw std::invalid_argument(message.str());
}

}  // namespace

HostTargetPhotometricResidual::HostTargetPhotometricResidual(const ImagePyramid& target_pyramid,
                                                             int level, const PinholeCamera& camera,
                                                             std::vector<HostPixel> pattern,
                                                             const ceres::LossFunction* loss,
                                                             ImageInterpolation interpolation)
    : target_pyramid_(target_pyramid),
      level_(level),
      camera_(camera),
      pattern_(std::move(pattern)),
      loss_(loss),
      interpolation_(interpolation) {
  if (pattern_.empty()) ThrowInvalid(__LINE__, "empty pattern");
  if (level < 0 || level >= target_pyramid.num_levels()) {
    ThrowInvalid(__LINE__, "level " + std::to_string(level) + " outside the pyramid");
  }
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) ThrowInvalid(__LINE__, "camera: " + camera_error);
  if (camera.width != target_pyramid.width(level) ||
      camera.height != target_pyramid.height(level)) {
    ThrowInvalid(__LINE__, "camera size differs from level " + std::to_string(level));
  }
  for (size_t k = 0; k < pattern_.size(); ++k) {
    const HostPixel& p = pattern_[k];
    if (!p.pixel_in_host.allFinite() || !std::isfinite(p.intensity_host) || !(p.sqrt_info >= 0.0) ||
        !std::isfinite(p.sqrt_info)) {
      ThrowInvalid(__LINE__, "pixel " + std::to_string(k) +
                                 " has a non-finite value or a "
                                 "negative sqrt_info");
    }
    rays_in_host_.push_back(camera_.Unproject(p.pixel_in_host));
  }
  if (interpolation_ == ImageInterpolation::kBicubic) {
    grid_ = std::make_unique<const IntensityGrid>(target_pyramid.IntensityData(level), 0,
                                                  target_pyramid.height(level), 0,
                                                  target_pyramid.width(level));
    bicubic_ = std::make_unique<const BicubicInterpolator>(*grid_);
  }
  set_num_residuals(static_cast<int>(pattern_.size()));
  *mutable_parameter_block_sizes() = {kPoseAmbientSize, kPoseAmbientSize, 1, kBrightnessSize,
                                      kBrightnessSize};
}

bool HostTargetPhotometricResidual::Evaluate(double const* const* parameters, double* residuals,
                                             double** jacobians) const {
  const SE3 host_from_world = PoseFromParameters(parameters[0]);
  const SE3 target_from_world = PoseFromParameters(parameters[1]);
  const SE3 target_from_host = target_from_world * host_from_world.Inverse();
  const Eigen::Matrix3d rotation = target_from_host.rotation_matrix();
  const Eigen::Vector3d& translation = target_from_host.translation();
  const double idepth = parameters[2][0];
  const double a_host = parameters[3][0];
  const double b_host = parameters[3][1];
  const double a_target = parameters[4][0];
  const double b_target = parameters[4][1];
  const double half_gain = 0.5 * (a_target - a_host);
  const double root_gain = std::exp(half_gain);  // e^{s}
  const double inverse_root_gain = 1.0 / root_gain;

  auto want = [&](int block) { return jacobians != nullptr && jacobians[block] != nullptr; };
  const bool any_pose_jacobian = want(0) || want(1);
  const int n = num_pixels();
  double host_tangent[kPoseTangentSize];
  double target_tangent[kPoseTangentSize];
  const MinusJacobianMatrix host_minus =
      want(0) ? PoseMinusJacobian(parameters[0]) : MinusJacobianMatrix::Zero();
  const MinusJacobianMatrix target_minus =
      want(1) ? PoseMinusJacobian(parameters[1]) : MinusJacobianMatrix::Zero();
  const double max_u = camera_.width - 1 - kSamplingBorder;
  const double max_v = camera_.height - 1 - kSamplingBorder;

  for (int k = 0; k < n; ++k) {
    const HostPixel& p = pattern_[k];
    const Eigen::Vector3d& ray = rays_in_host_[k];
    const Eigen::Vector3d q = rotation * ray + idepth * translation;
    const double x_over = q.x() / q.z();
    const double y_over = q.y() / q.z();
    const double u = camera_.fx * x_over + camera_.cx;
    const double v = camera_.fy * y_over + camera_.cy;
    const bool valid =
        q.z() > 0.0 && u >= kSamplingBorder && v >= kSamplingBorder && u < max_u && v < max_v;
    if (!valid) {
      residuals[k] = 0.0;
      if (want(0)) std::fill_n(jacobians[0] + k * kPoseAmbientSize, kPoseAmbientSize, 0.0);
      if (want(1)) std::fill_n(jacobians[1] + k * kPoseAmbientSize, kPoseAmbientSize, 0.0);
      if (want(2)) jacobians[2][k] = 0.0;
      if (want(3)) std::fill_n(jacobians[3] + k * kBrightnessSize, kBrightnessSize, 0.0);
      if (want(4)) std::fill_n(jacobians[4] + k * kBrightnessSize, kBrightnessSize, 0.0);
      continue;
    }
    double intensity_target = 0.0, gx = 0.0, gy = 0.0;
    const bool gradient = any_pose_jacobian || want(2);
    if (interpolation_ == ImageInterpolation::kBicubic) {
      // Ceres' grids are indexed (row, column) = (y, x).
      bicubic_->Evaluate(v, u, &intensity_target, gradient ? &gy : nullptr,
                         gradient ? &gx : nullptr);
    } else {
      const Eigen::Vector3f sample = target_pyramid_.Sample(level_, u, v);
      intensity_target = sample[0];
      gx = sample[1];
      gy = sample[2];
    }
    const double host_term = root_gain * (p.intensity_host - b_host);
    const double target_term = inverse_root_gain * (intensity_target - b_target);
    double scale = 1.0;
    residuals[k] = RobustifyRow(loss_, p.sqrt_info * (host_term - target_term), &scale);
    const double w = p.sqrt_info * scale;
    if (gradient) {
      // c = dr/dq = -w e^{-s} g^T dpi/dq.
      const double inv_z = 1.0 / q.z();
      const double gfx = gx * camera_.fx * inv_z;
      const double gfy = gy * camera_.fy * inv_z;
      const Eigen::Vector3d c =
          (-w * inverse_root_gain) * Eigen::Vector3d(gfx, gfy, -(gfx * x_over + gfy * y_over));
      if (want(1)) {
        // c [d I, -[q]x] = [d c, (q x c)^T].
        Eigen::Map<Eigen::Matrix<double, 6, 1>> row(target_tangent);
        row.head<3>() = idepth * c;
        row.tail<3>() = q.cross(c);
        LiftTangentJacobian(target_minus, target_tangent, 1, jacobians[1] + k * kPoseAmbientSize);
      }
      if (want(0)) {
        // c [-d R, R [ray]x] = [-d (R^T c)^T, ((R^T c) x ray)^T].
        const Eigen::Vector3d c_host = rotation.transpose() * c;
        Eigen::Map<Eigen::Matrix<double, 6, 1>> row(host_tangent);
        row.head<3>() = -idepth * c_host;
        row.tail<3>() = c_host.cross(ray);
        LiftTangentJacobian(host_minus, host_tangent, 1, jacobians[0] + k * kPoseAmbientSize);
      }
      if (want(2)) jacobians[2][k] = c.dot(translation);
    }
    const double da_target = 0.5 * w * (host_term + target_term);
    if (want(3)) {
      jacobians[3][k * kBrightnessSize] = -da_target;
      jacobians[3][k * kBrightnessSize + 1] = -w * root_gain;
    }
    if (want(4)) {
      jacobians[4][k * kBrightnessSize] = da_target;
      jacobians[4][k * kBrightnessSize + 1] = w * inverse_root_gain;
    }
  }
  return true;
}

}  // namespace pldvo
