#include "backend/mapping/line_stereo.h"

#include <Eigen/Dense>
#include <cmath>

namespace pldvo {

Eigen::Matrix<double, 2, 4> BackProjectedPlanes(const Eigen::Vector3d& line_in_ref,
                                                const Eigen::Vector3d& line_in_cur,
                                                const PinholeCamera& camera,
                                                const SE3& cur_from_ref) {
  const Eigen::Matrix3d k = camera.K();
  Eigen::Matrix<double, 2, 4> planes;
  planes.row(0) << line_in_ref.transpose() * k, 0.0;
  planes.row(1) << line_in_cur.transpose() * k * cur_from_ref.rotation_matrix(),
      line_in_cur.transpose() * k * cur_from_ref.translation();
  return planes;
}

bool TriangulateLine(const Eigen::Matrix<double, 2, 4>& planes, Line3d* line) {
  const Eigen::Vector3d n1 = planes.row(0).head<3>().transpose();
  const Eigen::Vector3d n2 = planes.row(1).head<3>().transpose();
  const Eigen::Vector3d direction = n1.cross(n2);
  if (!(direction.norm() > 1e-9 * n1.norm() * n2.norm())) return false;
  // Minimum-norm X with N X = -offsets: X = N^T (N N^T)^-1 (-offsets).
  Eigen::Matrix<double, 2, 3> n;
  n.row(0) = n1.transpose();
  n.row(1) = n2.transpose();
  const Eigen::Vector2d offsets(planes(0, 3), planes(1, 3));
  line->point_in_ref = n.transpose() * (n * n.transpose()).ldlt().solve(-offsets);
  line->direction = direction.normalized();
  return true;
}

bool IdepthFromLinePlane(const EpipolarGeometry& geometry, const Eigen::Vector2d& pixel_in_ref,
                         const Eigen::Vector3d& line_in_cur, double* idepth) {
  const double numerator = line_in_cur.dot(geometry.InfinityPoint(pixel_in_ref));
  const double denominator = line_in_cur.dot(geometry.ScaledTranslation());
  // |l2^T K t| is the distance (in pixels times z) of the epipole from the line; tiny means the
  // epipolar plane contains the edge.
  if (!(std::abs(denominator) > 1e-12 * (1.0 + std::abs(numerator)))) return false;
  *idepth = -numerator / denominator;
  return std::isfinite(*idepth);
}

double LineDisparityVar(double line_position_var, double epipolar_position_var, double theta) {
  const double s = std::sin(theta), c = std::cos(theta);
  return (line_position_var + epipolar_position_var * c * c) / (s * s);
}

StereoStatus LineGuidedStereo(const EpipolarGeometry& geometry, const Eigen::Vector2d& pixel_in_ref,
                              const Eigen::Vector2d& pixel_on_line, double ref_line_position_var,
                              const LineWithCovariance& line_in_cur, double idepth_min,
                              double idepth_max, const MappingOptions& options,
                              const ImagePyramid* current, const EpipolarPatch* patch,
                              StereoObservation* observation) {
  // The epipolar line of x in the current frame, A x B (depth-independent direction), so that
  // near-parallel configurations are caught before the ill-conditioned intersection.
  const Eigen::Vector3d epipolar_line =
      geometry.InfinityPoint(pixel_on_line).cross(geometry.ScaledTranslation());
  const double epipolar_norm = epipolar_line.head<2>().norm();
  if (!(epipolar_norm > 1e-12)) return StereoStatus::kBadGeometry;
  const Eigen::Vector2d epipolar_dir =
      Eigen::Vector2d(-epipolar_line.y(), epipolar_line.x()) / epipolar_norm;
  const double sin_theta = std::abs(line_in_cur.line.head<2>().dot(epipolar_dir));
  const double min_angle = options.min_line_epipolar_angle_deg * M_PI / 180.0;
  if (sin_theta < std::sin(min_angle) || sin_theta <= 1e-9) {
    return StereoStatus::kLineIllConditioned;
  }
  double idepth = 0.0;
  if (!IdepthFromLinePlane(geometry, pixel_on_line, line_in_cur.line, &idepth)) {
    return StereoStatus::kLineIllConditioned;
  }
  Eigen::Vector2d match_on_line, match;
  if (idepth < 0.0 || !geometry.Project(pixel_on_line, idepth, &match_on_line) ||
      !geometry.Project(pixel_in_ref, idepth, &match)) {
    return StereoStatus::kLineOutOfRange;
  }
  const double jacobian_norm = geometry.IdepthJacobian(pixel_on_line, idepth).norm();
  if (!(jacobian_norm > 1e-9)) return StereoStatus::kBadGeometry;
  if (idepth < idepth_min || idepth > idepth_max) return StereoStatus::kLineOutOfRange;
  if (current != nullptr && patch != nullptr && options.line_stereo_check_ssd) {
    const double ssd = PatchSsd(*current, *patch, match);
    if (!std::isfinite(ssd)) return StereoStatus::kOutside;
    if (std::sqrt(ssd / 5.0) > options.max_ssd_rms) return StereoStatus::kLargeError;
    observation->ssd = ssd;
  }
  const Eigen::Vector3d match_h(match_on_line.x(), match_on_line.y(), 1.0);
  const double line_position_var = match_h.dot(line_in_cur.cov * match_h);
  const double theta = std::asin(std::min(1.0, sin_theta));
  const double epipolar_var =
      options.sigma_epipolar_px * options.sigma_epipolar_px +
      geometry.PoseOffsetVar(pixel_on_line, idepth,
                             Eigen::Vector2d(-epipolar_dir.y(), epipolar_dir.x()));
  const double disparity_var =
      LineDisparityVar(line_position_var + ref_line_position_var, epipolar_var, theta);
  const double alpha_sq = 1.0 / (jacobian_norm * jacobian_norm);
  observation->idepth = idepth;
  observation->disparity_var = disparity_var;
  observation->idepth_var = disparity_var * alpha_sq;
  observation->shared_idepth_var = LineDisparityVar(ref_line_position_var, 0.0, theta) * alpha_sq;
  observation->pixel_in_cur = match;
  return StereoStatus::kOk;
}

}  // namespace pldvo
