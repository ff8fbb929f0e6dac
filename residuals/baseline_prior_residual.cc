#include "residuals/baseline_prior_residual.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/se3.h"
#include "residuals/se3_manifold.h"

namespace pldvo {

BaselinePriorResidual::BaselinePriorResidual(double baseline, double sigma)
    : baseline_(baseline), sigma_(sigma) {
  if (!(baseline > 0.0) || !std::isfinite(baseline) || !(sigma > 0.0) || !std::isfinite(sigma)) {
    std::ostringstream message;
    message << __FILE__ << ":" << __LINE__
            << ": BaselinePriorResidual: baseline and sigma must be positive and finite (got "
            << baseline << ", " << sigma << ")";
    throw std::invalid_argument(message.str());
  }
}

bool BaselinePriorResidual::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const SE3 a = PoseFromParameters(parameters[0]);
  const SE3 b = PoseFromParameters(parameters[1]);
  const Eigen::Matrix3d rotation_a = a.rotation_matrix();
  const Eigen::Matrix3d rotation_b = b.rotation_matrix();
  const Eigen::Vector3d center_a = -rotation_a.transpose() * a.translation();
  const Eigen::Vector3d center_b = -rotation_b.transpose() * b.translation();
  const Eigen::Vector3d offset = center_b - center_a;
  const double length = offset.norm();
  if (!(length >= 1e-12)) return false;
  residuals[0] = (length - baseline_) / sigma_;
  if (jacobians == nullptr) return true;
  const Eigen::Vector3d u = offset / length;
  const Eigen::Matrix3d* rotations[2] = {&rotation_a, &rotation_b};
  const double signs[2] = {1.0, -1.0};
  for (int k = 0; k < 2; ++k) {
    if (jacobians[k] == nullptr) continue;
    double tangent[6] = {0, 0, 0, 0, 0, 0};
    Eigen::Map<Eigen::Matrix<double, 1, 3>> j_v(tangent);
    j_v = (signs[k] / sigma_) * u.transpose() * rotations[k]->transpose();
    LiftTangentJacobian(PoseMinusJacobian(parameters[k]), tangent, 1, jacobians[k]);
  }
  return true;
}

}  // namespace pldvo
