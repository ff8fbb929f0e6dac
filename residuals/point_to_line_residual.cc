#include "residuals/point_to_line_residual.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "residuals/batched_reprojection.h"
#include "residuals/robustify.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

[[noreturn]] void ThrowInvalid(int line, const std::string& what) {
  std::ostringstream message;
  message << __FILE__ << ":" << line << ": PointToLineResidual: " << what;
  throw std::invalid_argument(message.str());
}

// One row: residual and (optionally) its tangent Jacobian. Returns validity.
inline bool PointToLineRow(const PinholeCamera& camera, const PointToLineObservation& o,
                           const Eigen::Vector3d& ray_in_ref, const Eigen::Matrix3d& rotation,
                           const Eigen::Vector3d& translation, const ceres::LossFunction* loss,
                           double* residual, double* jacobian_tangent) {
  const Eigen::Vector3d q = rotation * ray_in_ref + o.idepth * translation;
  const double u_over = q.x() / q.z();
  const double v_over = q.y() / q.z();
  const double u = camera.fx * u_over + camera.cx;
  const double v = camera.fy * v_over + camera.cy;
  if (!(q.z() > 0.0) ||
      !(u >= 0.0 && v >= 0.0 && u <= camera.width - 1 && v <= camera.height - 1)) {
    *residual = 0.0;
    if (jacobian_tangent != nullptr) std::fill(jacobian_tangent, jacobian_tangent + 6, 0.0);
    return false;
  }
  const Eigen::Vector3d& l = o.line_in_cur;
  double scale;
  *residual = RobustifyRow(loss, o.sqrt_info * (l.x() * u + l.y() * v + l.z()), &scale);
  if (jacobian_tangent != nullptr) {
    // c = (a, b) dpi/dq (1x3); dg/dxi = w [d c, (q x c)^T].
    const double inv_z = 1.0 / q.z();
    const double afx = l.x() * camera.fx * inv_z;
    const double bfy = l.y() * camera.fy * inv_z;
    const Eigen::Vector3d c(afx, bfy, -(afx * u_over + bfy * v_over));
    const double w = o.sqrt_info * scale;
    Eigen::Map<Eigen::Matrix<double, 6, 1>> row(jacobian_tangent);
    row.head<3>() = (w * o.idepth) * c;
    row.tail<3>() = w * q.cross(c);
  }
  return true;
}

}  // namespace

PointToLineResidual::PointToLineResidual(const PinholeCamera& camera,
                                         std::vector<PointToLineObservation> observations,
                                         const ceres::LossFunction* loss, SharedLineError shared)
    : camera_(camera),
      observations_(std::move(observations)),
      loss_(loss),
      shared_(std::move(shared)) {
  if (observations_.empty()) ThrowInvalid(__LINE__, "empty batch");
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) ThrowInvalid(__LINE__, "camera: " + camera_error);
  rays_in_ref_.reserve(observations_.size());
  for (size_t i = 0; i < observations_.size(); ++i) {
    const PointToLineObservation& o = observations_[i];
    if (!o.pixel_in_ref.allFinite() || !o.line_in_cur.allFinite() || !(o.idepth >= 0.0) ||
        !std::isfinite(o.idepth) || !(o.sqrt_info >= 0.0) || !std::isfinite(o.sqrt_info)) {
      ThrowInvalid(__LINE__, "observation " + std::to_string(i) +
                                 " has a non-finite value, a negative idepth or sqrt_info");
    }
    if (!(std::abs(o.line_in_cur.head<2>().squaredNorm() - 1.0) <= 1e-6)) {
      ThrowInvalid(__LINE__, "observation " + std::to_string(i) +
                                 ": line must be normalised to a^2 + b^2 = 1");
    }
    rays_in_ref_.push_back(camera_.Unproject(o.pixel_in_ref));
  }
  if (shared_.v.rows() != 0 && shared_.v.rows() != static_cast<int>(observations_.size())) {
    ThrowInvalid(__LINE__, "shared line error has " + std::to_string(shared_.v.rows()) +
                               " rows for " + std::to_string(observations_.size()) +
                               " observations");
  }
  if (!shared_.v.allFinite() || !shared_.m.allFinite()) {
    ThrowInvalid(__LINE__, "shared line error is not finite");
  }
  valid_.assign(observations_.size(), 0);
  tangent_.assign(observations_.size() * kPoseTangentSize, 0.0);
  set_num_residuals(static_cast<int>(observations_.size()));
  mutable_parameter_block_sizes()->push_back(kPoseAmbientSize);
}

bool PointToLineResidual::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  double* jacobian = (jacobians != nullptr) ? jacobians[0] : nullptr;
  EvaluateTangent(PoseFromParameters(parameters[0]), residuals,
                  jacobian != nullptr ? tangent_.data() : nullptr, valid_.data());
  if (jacobian != nullptr) {
    LiftTangentJacobian(PoseMinusJacobian(parameters[0]), tangent_.data(), num_observations(),
                        jacobian);
  }
  return true;
}

bool PointToLineResidual::EvaluatePoseTangent(double const* const* parameters, double* residuals,
                                              double* jacobian_tangent) const {
  EvaluateTangent(PoseFromParameters(parameters[0]), residuals, jacobian_tangent, valid_.data());
  return true;
}

void PointToLineResidual::EvaluateTangent(const SE3& cur_from_ref, double* residuals,
                                          double* jacobian_tangent, std::uint8_t* valid) const {
  const Eigen::Matrix3d rotation = cur_from_ref.rotation_matrix();
  const Eigen::Vector3d& translation = cur_from_ref.translation();
  const int n = num_observations();
  const bool mix = shared_.v.rows() != 0;
  // Mixed rows get the robust loss after the mix.
  const ceres::LossFunction* row_loss = mix ? nullptr : loss_;
  std::uint8_t* flags = valid != nullptr ? valid : valid_.data();
  for (int i = 0; i < n; ++i) {
    flags[i] = PointToLineRow(
        camera_, observations_[i], rays_in_ref_[i], rotation, translation, row_loss, residuals + i,
        jacobian_tangent != nullptr ? jacobian_tangent + i * kPoseTangentSize : nullptr);
  }
  if (!mix) return;
  // r = e - V M V^T e and J = J_e - V M V^T J_e (invalid rows: 0 in, 0 out), then the loss.
  using TangentRows = Eigen::Matrix<double, Eigen::Dynamic, kPoseTangentSize, Eigen::RowMajor>;
  const Eigen::Vector2d coeffs =
      shared_.m * (shared_.v.transpose() * Eigen::Map<const Eigen::VectorXd>(residuals, n));
  Eigen::Matrix<double, 2, kPoseTangentSize> jacobian_coeffs =
      Eigen::Matrix<double, 2, kPoseTangentSize>::Zero();
  if (jacobian_tangent != nullptr) {
    jacobian_coeffs =
        shared_.m * (shared_.v.transpose() *
                     Eigen::Map<const TangentRows>(jacobian_tangent, n, kPoseTangentSize));
  }
  for (int i = 0; i < n; ++i) {
    double* row = jacobian_tangent != nullptr ? jacobian_tangent + i * kPoseTangentSize : nullptr;
    if (!flags[i]) continue;  // already 0
    double scale;
    residuals[i] = RobustifyRow(loss_, residuals[i] - shared_.v.row(i).dot(coeffs), &scale);
    if (row != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 1, kPoseTangentSize>> jacobian_row(row);
      jacobian_row = scale * (jacobian_row - shared_.v.row(i) * jacobian_coeffs);
    }
  }
}

std::vector<Eigen::Vector2d> PointToLineResidual::ReprojectedPixels(
    const SE3& cur_from_ref, std::vector<std::uint8_t>* valid) const {
  return ReprojectRays(camera_, rays_in_ref_, observations_, cur_from_ref, valid,
                       [&](double* residuals, std::uint8_t* row_valid) {
                         EvaluateTangent(cur_from_ref, residuals, nullptr, row_valid);
                       });
}

int PointToLineResidual::num_valid() const { return CountValid(valid_); }

}  // namespace pldvo
