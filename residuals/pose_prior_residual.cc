#include "residuals/pose_prior_residual.h"

#include <Eigen/Eigenvalues>
#include <stdexcept>
#include <utility>

#include "residuals/se3_manifold.h"

namespace pldvo {

PosePriorResidual::PosePriorResidual(std::vector<SE3> linearization_poses,
                                     const Eigen::MatrixXd& information,
                                     const Eigen::VectorXd& gradient)
    : linearization_poses_(std::move(linearization_poses)) {
  const int dimension = kPoseTangentSize * static_cast<int>(linearization_poses_.size());
  if (dimension == 0 || information.rows() != dimension || information.cols() != dimension ||
      gradient.size() != dimension || !information.allFinite() || !gradient.allFinite()) {
    throw std::invalid_argument(
        "PosePriorResidual: information must be 6K x 6K and gradient 6K, finite");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
      0.5 * (information + information.transpose()));
  const Eigen::VectorXd& values = eigen.eigenvalues();  // increasing
  const double largest = values(dimension - 1);
  if (!(largest > 0.0)) {
    throw std::invalid_argument("PosePriorResidual: information has no positive eigenvalue");
  }
  int first = 0;
  while (values(first) <= 1e-12 * largest) ++first;
  const int rows = dimension - first;
  const Eigen::MatrixXd vectors = eigen.eigenvectors().rightCols(rows);
  const Eigen::VectorXd kept = values.tail(rows);
  sqrt_information_ = kept.cwiseSqrt().asDiagonal() * vectors.transpose();
  offset_ = kept.cwiseSqrt().cwiseInverse().asDiagonal() * (vectors.transpose() * gradient);
  set_num_residuals(rows);
  for (size_t k = 0; k < linearization_poses_.size(); ++k) {
    mutable_parameter_block_sizes()->push_back(kPoseAmbientSize);
  }
}

bool PosePriorResidual::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const int num_poses = static_cast<int>(linearization_poses_.size());
  const int rows = num_residuals();
  Eigen::VectorXd deltas(kPoseTangentSize * num_poses);
  for (int k = 0; k < num_poses; ++k) {
    deltas.segment<kPoseTangentSize>(kPoseTangentSize * k) =
        (PoseFromParameters(parameters[k]) * linearization_poses_[k].Inverse()).Log();
  }
  Eigen::Map<Eigen::VectorXd>(residuals, rows) = sqrt_information_ * deltas + offset_;
  if (jacobians == nullptr) return true;
  Eigen::Matrix<double, Eigen::Dynamic, kPoseTangentSize, Eigen::RowMajor> tangent(
      rows, kPoseTangentSize);
  for (int k = 0; k < num_poses; ++k) {
    if (jacobians[k] == nullptr) continue;
    tangent = sqrt_information_.middleCols<kPoseTangentSize>(kPoseTangentSize * k) *
              InverseLeftJacobianSE3(deltas.segment<kPoseTangentSize>(kPoseTangentSize * k));
    LiftTangentJacobian(PoseMinusJacobian(parameters[k]), tangent.data(), rows, jacobians[k]);
  }
  return true;
}

}  // namespace pldvo
