#include "residuals/covariance_models.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pldvo {
namespace {

// q = R K^-1 (x; 1) + d t: proportional to the point in the current camera for d > 0.
Eigen::Vector3d ScaledPointInCur(const PinholeCamera& camera, const SE3& cur_from_ref,
                                 const Eigen::Vector2d& pixel_in_ref, double idepth) {
  return cur_from_ref.rotation() * camera.Unproject(pixel_in_ref) +
         idepth * cur_from_ref.translation();
}

}  // namespace

bool Reproject(const PinholeCamera& camera, const SE3& cur_from_ref,
               const Eigen::Vector2d& pixel_in_ref, double idepth, Eigen::Vector2d* pixel_in_cur) {
  const Eigen::Vector3d q = ScaledPointInCur(camera, cur_from_ref, pixel_in_ref, idepth);
  if (!(q.z() > 0.0)) return false;
  *pixel_in_cur = camera.Project(q);
  return true;
}

Eigen::Vector2d ReprojectionIdepthJacobian(const PinholeCamera& camera, const SE3& cur_from_ref,
                                           const Eigen::Vector2d& pixel_in_ref, double idepth) {
  const Eigen::Vector3d q = ScaledPointInCur(camera, cur_from_ref, pixel_in_ref, idepth);
  return camera.ProjectJacobian(q) * cur_from_ref.translation();
}

double PhotometricVariance(double sigma_intensity, const Eigen::Vector2d& gradient_cur,
                           const Eigen::Vector2d& pixel_idepth_jacobian, double idepth_var) {
  const double dr_didepth = -gradient_cur.dot(pixel_idepth_jacobian);
  return 2.0 * sigma_intensity * sigma_intensity + dr_didepth * dr_didepth * idepth_var;
}

LineWithCovariance FitLine(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, double sigma_px) {
  if (!((p2 - p1).norm() >= 1e-9) || !p1.allFinite() || !p2.allFinite()) {
    std::ostringstream message;
    message << __FILE__ << ":" << __LINE__ << ": FitLine: degenerate endpoints (" << p1.transpose()
            << ") and (" << p2.transpose() << ")";
    throw std::invalid_argument(message.str());
  }
  if (!(sigma_px >= 0.0) || !std::isfinite(sigma_px)) {
    std::ostringstream message;
    message << __FILE__ << ":" << __LINE__ << ": FitLine: sigma_px must be >= 0, got " << sigma_px;
    throw std::invalid_argument(message.str());
  }
  const Eigen::Vector3d h1(p1.x(), p1.y(), 1.0);
  const Eigen::Vector3d h2(p2.x(), p2.y(), 1.0);
  const Eigen::Vector3d raw = h1.cross(h2);
  const double norm = raw.head<2>().norm();  // = |p2 - p1|
  LineWithCovariance result;
  result.line = raw / norm;

  // d raw / d(p1, p2): raw = -[h2]x h1 = [h1]x h2, and only the first two homogeneous
  // coordinates are noisy.
  Eigen::Matrix<double, 3, 4> draw_dp;
  draw_dp.leftCols<2>() = -Hat(h2).leftCols<2>();
  draw_dp.rightCols<2>() = Hat(h1).leftCols<2>();
  // d (raw / |raw_ab|) / d raw = (I - l (l_a, l_b, 0)) / |raw_ab|.
  Eigen::Matrix3d dl_draw = Eigen::Matrix3d::Identity();
  dl_draw.leftCols<2>() -= result.line * result.line.head<2>().transpose();
  dl_draw /= norm;
  const Eigen::Matrix<double, 3, 4> dl_dp = dl_draw * draw_dp;
  result.cov = sigma_px * sigma_px * dl_dp * dl_dp.transpose();
  return result;
}

Eigen::Matrix3d ReprojectedPixelCovariance(const Eigen::Vector2d& pixel_idepth_jacobian,
                                           double idepth_var) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov.topLeftCorner<2, 2>() =
      idepth_var * pixel_idepth_jacobian * pixel_idepth_jacobian.transpose();
  return cov;
}

Eigen::Matrix3d ReprojectedPixelCovariance(const PinholeCamera& camera, const SE3& cur_from_ref,
                                           const Eigen::Vector2d& pixel_in_ref, double idepth,
                                           double idepth_var) {
  return ReprojectedPixelCovariance(
      ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, idepth), idepth_var);
}

Eigen::Matrix<double, 3, 2> LineCovarianceFactor(const Eigen::Matrix3d& line_cov) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(line_cov);  // ascending eigenvalues
  Eigen::Matrix<double, 3, 2> factor;
  for (int k = 0; k < 2; ++k) {
    factor.col(k) =
        eigen.eigenvectors().col(k + 1) * std::sqrt(std::max(eigen.eigenvalues()[k + 1], 0.0));
  }
  return factor;
}

double PointToLineVariance(const Eigen::Vector3d& line, const Eigen::Matrix3d& line_cov,
                           const Eigen::Vector2d& pixel_cur, const Eigen::Matrix3d& pixel_cov) {
  const Eigen::Vector3d x(pixel_cur.x(), pixel_cur.y(), 1.0);
  return line.dot(pixel_cov * line) + x.dot(line_cov * x);
}

}  // namespace pldvo
