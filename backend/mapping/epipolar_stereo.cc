#include "backend/mapping/epipolar_stereo.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace pldvo {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinZ = 1e-6;

}  // namespace

EpipolarGeometry::EpipolarGeometry(const PinholeCamera& camera, const SE3& cur_from_ref,
                                   const Matrix6d& pose_covariance)
    : camera_(camera),
      cur_from_ref_(cur_from_ref),
      rotation_(cur_from_ref.rotation_matrix()),
      pose_covariance_(pose_covariance),
      has_pose_covariance_(!pose_covariance.isZero(0.0)) {
  const Eigen::Matrix3d k = camera.K();
  krki_ = k * rotation_ * k.inverse();
  kt_ = k * cur_from_ref.translation();
  const Eigen::Vector3d centre_in_ref = -(rotation_.transpose() * cur_from_ref.translation());
  epipole_in_ref_h_ = k * centre_in_ref;
}

bool EpipolarGeometry::Project(const Eigen::Vector2d& pixel_in_ref, double idepth,
                               Eigen::Vector2d* pixel_in_cur) const {
  const Eigen::Vector3d q = InfinityPoint(pixel_in_ref) + idepth * kt_;
  if (q.z() <= kMinZ * (1.0 + std::abs(idepth))) return false;
  *pixel_in_cur = q.head<2>() / q.z();
  return true;
}

Eigen::Vector2d EpipolarGeometry::IdepthJacobian(const Eigen::Vector2d& pixel_in_ref,
                                                 double idepth) const {
  const Eigen::Vector3d q = InfinityPoint(pixel_in_ref) + idepth * kt_;
  return (kt_.head<2>() * q.z() - q.head<2>() * kt_.z()) / (q.z() * q.z());
}

double EpipolarGeometry::IdepthFromCurPixel(const Eigen::Vector2d& pixel_in_ref,
                                            const Eigen::Vector2d& pixel_in_cur,
                                            const Eigen::Vector2d& direction_in_cur) const {
  // u = (A_x + d B_x) / (A_z + d B_z)  =>  d = (A_x - u A_z) / (u B_z - B_x), likewise in y.
  const Eigen::Vector3d a = InfinityPoint(pixel_in_ref);
  const int c = std::abs(direction_in_cur.x()) >= std::abs(direction_in_cur.y()) ? 0 : 1;
  const double p = pixel_in_cur[c];
  return (a[c] - p * a.z()) / (p * kt_.z() - kt_[c]);
}

bool EpipolarGeometry::EpipolarDirectionInRef(const Eigen::Vector2d& pixel_in_ref,
                                              Eigen::Vector2d* dir) const {
  // The line through x and the epipole e = (K c); e may be at infinity (c_z = 0).
  const Eigen::Vector2d d = epipole_in_ref_h_.head<2>() - pixel_in_ref * epipole_in_ref_h_.z();
  const double norm = d.norm();
  if (!(norm > 1e-9 * (1.0 + epipole_in_ref_h_.norm()))) return false;
  *dir = d / norm;
  return true;
}

double EpipolarGeometry::PoseOffsetVar(const Eigen::Vector2d& pixel_in_ref, double idepth,
                                       const Eigen::Vector2d& normal_in_cur) const {
  if (!has_pose_covariance_) return 0.0;
  const Eigen::Vector3d y =
      rotation_ * camera_.Unproject(pixel_in_ref) + idepth * cur_from_ref_.translation();
  const Eigen::RowVector3d n_dpi = normal_in_cur.transpose() * camera_.ProjectJacobian(y);
  // dY / d(t; w) = [d I, -[Y]x], and n_dpi (-[Y]x) w = w . (Y x n_dpi).
  Eigen::Matrix<double, 1, 6> row;
  row.head<3>() = idepth * n_dpi;
  row.tail<3>() = y.cross(n_dpi.transpose()).transpose();
  return row * pose_covariance_ * row.transpose();
}

const char* StereoStatusName(StereoStatus status) {
  switch (status) {
    case StereoStatus::kOk:
      return "ok";
    case StereoStatus::kOutside:
      return "outside";
    case StereoStatus::kBadGeometry:
      return "bad_geometry";
    case StereoStatus::kSearchTooLong:
      return "search_too_long";
    case StereoStatus::kTruncated:
      return "truncated";
    case StereoStatus::kNotUnique:
      return "not_unique";
    case StereoStatus::kLargeError:
      return "large_error";
    case StereoStatus::kIntervalEnd:
      return "interval_end";
    case StereoStatus::kLineIllConditioned:
      return "line_ill_conditioned";
    case StereoStatus::kLineOutOfRange:
      return "line_out_of_range";
  }
  return "unknown";
}

StereoStatus MakeEpipolarPatch(const ImagePyramid& keyframe, const EpipolarGeometry& geometry,
                               const Eigen::Vector2d& pixel_in_ref, double idepth_centre,
                               const MappingOptions& options, EpipolarPatch* patch) {
  Eigen::Vector2d dir;
  if (!geometry.EpipolarDirectionInRef(pixel_in_ref, &dir)) return StereoStatus::kBadGeometry;
  const Eigen::Vector2d lo = pixel_in_ref - 2.0 * dir, hi = pixel_in_ref + 2.0 * dir;
  if (!keyframe.CanSample(0, lo.x(), lo.y()) || !keyframe.CanSample(0, hi.x(), hi.y()) ||
      !keyframe.CanSample(0, pixel_in_ref.x(), pixel_in_ref.y())) {
    return StereoStatus::kOutside;
  }
  const Eigen::Vector3f centre = keyframe.Sample(0, pixel_in_ref.x(), pixel_in_ref.y());
  const double grad_norm = std::hypot(centre.y(), centre.z());
  if (!(grad_norm > 0.0)) return StereoStatus::kBadGeometry;
  patch->gradient_epipolar_cos = std::abs(centre.y() * dir.x() + centre.z() * dir.y()) / grad_norm;
  if (patch->gradient_epipolar_cos < options.min_gradient_epipolar_cos) {
    return StereoStatus::kBadGeometry;
  }
  for (int j = -2; j <= 2; ++j) {
    const Eigen::Vector2d p = pixel_in_ref + j * dir;
    patch->ref[j + 2] = keyframe.SampleIntensity(0, p.x(), p.y());
  }
  Eigen::Vector2d p0, p1;
  if (!geometry.Project(pixel_in_ref, idepth_centre, &p0) ||
      !geometry.Project(pixel_in_ref + dir, idepth_centre, &p1)) {
    return StereoStatus::kOutside;
  }
  const Eigen::Vector2d step = p1 - p0;
  const double scale = step.norm();
  if (!(scale <= options.max_epipolar_scale && scale >= 1.0 / options.max_epipolar_scale)) {
    return StereoStatus::kBadGeometry;
  }
  patch->dir_ref = dir;
  patch->step_cur = step;
  return StereoStatus::kOk;
}

double PatchSsd(const ImagePyramid& current, const EpipolarPatch& patch,
                const Eigen::Vector2d& pixel_in_cur) {
  const Eigen::Vector2d lo = pixel_in_cur - 2.0 * patch.step_cur;
  const Eigen::Vector2d hi = pixel_in_cur + 2.0 * patch.step_cur;
  if (!current.CanSample(0, lo.x(), lo.y()) || !current.CanSample(0, hi.x(), hi.y())) return kInf;
  double ssd = 0.0;
  for (int j = -2; j <= 2; ++j) {
    const Eigen::Vector2d p = pixel_in_cur + j * patch.step_cur;
    const double r = current.SampleIntensity(0, p.x(), p.y()) - patch.ref[j + 2];
    ssd += r * r;
  }
  return ssd;
}

double GeometricDisparityVar(const EpipolarPatch& patch, double epipolar_position_var) {
  const double c = std::max(patch.gradient_epipolar_cos, 1e-6);
  return epipolar_position_var / (c * c);
}

double PhotometricDisparityVar(const ImagePyramid& current, const EpipolarPatch& patch,
                               const Eigen::Vector2d& pixel_in_cur, double sigma_intensity) {
  // g_p^2: mean squared finite difference of the five current samples per current pixel.
  double samples[5];
  for (int j = -2; j <= 2; ++j) {
    const Eigen::Vector2d p = pixel_in_cur + j * patch.step_cur;
    if (!current.CanSample(0, p.x(), p.y())) return kInf;
    samples[j + 2] = current.SampleIntensity(0, p.x(), p.y());
  }
  const double step_sq = patch.step_cur.squaredNorm();
  double grad_sq = 0.0;
  for (int j = 0; j < 4; ++j)
    grad_sq += (samples[j + 1] - samples[j]) * (samples[j + 1] - samples[j]);
  grad_sq /= 4.0 * step_sq;
  return 2.0 * sigma_intensity * sigma_intensity / std::max(grad_sq, 1e-9);
}

StereoStatus SearchEpipolarSsd(const ImagePyramid& current, const EpipolarGeometry& geometry,
                               const EpipolarPatch& patch, const Eigen::Vector2d& pixel_in_ref,
                               double idepth_min, double idepth_max, const MappingOptions& options,
                               StereoObservation* observation) {
  Eigen::Vector2d p_far, p_near;
  // Ends of the interval beyond which a match could lie: not the global bounds, nor the current
  // camera's plane.
  const bool far_end_open = idepth_min > options.min_idepth;
  bool near_end_open = idepth_max < options.max_idepth;
  if (!geometry.Project(pixel_in_ref, idepth_min, &p_far)) return StereoStatus::kOutside;
  if (!geometry.Project(pixel_in_ref, idepth_max, &p_near)) {
    near_end_open = false;
    // The upper bound lies behind the current camera: search up to just before its plane.
    const Eigen::Vector3d a = geometry.InfinityPoint(pixel_in_ref);
    const Eigen::Vector3d& b = geometry.ScaledTranslation();
    if (!(b.z() < 0.0)) return StereoStatus::kOutside;
    const double d_plane = -a.z() / b.z();  // q_z = 0
    idepth_max = idepth_min + 0.9 * (d_plane - idepth_min);
    if (!geometry.Project(pixel_in_ref, idepth_max, &p_near)) return StereoStatus::kOutside;
  }
  Eigen::Vector2d direction = p_near - p_far;
  double length = direction.norm();
  if (length > options.max_search_length_px) return StereoStatus::kSearchTooLong;
  if (length > 1e-9) {
    direction /= length;
  } else {
    direction = patch.step_cur.normalized();
  }
  const Eigen::Vector2d normal(-direction.y(), direction.x());
  Eigen::Vector2d start = p_far;
  if (length < options.min_search_length_px) {
    start = 0.5 * (p_far + p_near) - 0.5 * options.min_search_length_px * direction;
    length = options.min_search_length_px;
  }
  // The step is the patch's sample spacing |step_cur| (which lies along the epipolar line)
  // divided by n = round(|step_cur| / ssd_search_step_px): then sample j of step k is line
  // sample k + j n (in the order of step_cur), and every line sample is interpolated once
  // (Engel 2013 steps by the sample spacing, n = 1). The uniqueness test and the ambiguity
  // spread leave out the steps within 2 px of the best.
  const double spacing = patch.step_cur.norm();
  const int n = std::max(1, static_cast<int>(std::lround(spacing / options.ssd_search_step_px)));
  const int sample_stride = patch.step_cur.dot(direction) < 0.0 ? -n : n;
  const double step_px = spacing / n;
  direction *= step_px;
  const int near_best = static_cast<int>(std::lround(2.0 / step_px));
  const int num_steps = static_cast<int>(std::floor(length / step_px)) + 1;
  // Small fixed buffers: the steps plus the 2 n samples beyond each end. MappingOptions::Check
  // bounds the count at the nominal step; a finer actual step can exceed it (kSearchTooLong).
  constexpr int kMaxSamples = 4096 + 256;
  const int num_samples = num_steps + 4 * n;
  if (num_samples > kMaxSamples) return StereoStatus::kSearchTooLong;
  float samples[kMaxSamples];
  // The image is convex: with both ends inside (with a margin for rounding) so is every sample,
  // and the per-sample test can go.
  const Eigen::Vector2d first = start - (2 * n) * direction;
  const Eigen::Vector2d last = start + (num_samples - 1 - 2 * n) * direction;
  constexpr double kMargin = 1e-6;
  const bool inside = current.CanSample(0, first.x() - kMargin, first.y() - kMargin) &&
                      current.CanSample(0, first.x() + kMargin, first.y() + kMargin) &&
                      current.CanSample(0, last.x() - kMargin, last.y() - kMargin) &&
                      current.CanSample(0, last.x() + kMargin, last.y() + kMargin);
  for (int m = 0; m < num_samples; ++m) {
    const Eigen::Vector2d p = start + (m - 2 * n) * direction;
    if (!inside && !current.CanSample(0, p.x(), p.y())) return StereoStatus::kTruncated;
    samples[m] = current.SampleIntensity(0, p.x(), p.y());
  }
  double ssd[kMaxSamples];
  int best = -1;
  for (int k = 0; k < num_steps; ++k) {
    const float* centre = samples + k + 2 * n;
    double sum = 0.0;
    for (int j = -2; j <= 2; ++j) {
      const double r = centre[j * sample_stride] - patch.ref[j + 2];
      sum += r * r;
    }
    ssd[k] = sum;
    if (best < 0 || ssd[k] < ssd[best]) best = k;
  }
  if (best < 0) return StereoStatus::kOutside;
  double second = kInf;
  for (int k = 0; k < num_steps; ++k) {
    if (std::abs(k - best) > near_best) second = std::min(second, ssd[k]);
  }
  if (std::sqrt(ssd[best] / 5.0) > options.max_ssd_rms) return StereoStatus::kLargeError;
  if (options.ssd_interval_end != MappingOptions::IntervalEndMinimum::kAccept &&
      ((best == 0 && far_end_open) || (best == num_steps - 1 && near_end_open))) {
    return StereoStatus::kIntervalEnd;
  }
  if (second < options.ssd_uniqueness_ratio * ssd[best]) return StereoStatus::kNotUnique;
  // Sub-pixel: vertex of the parabola through the neighbouring SSDs.
  double offset = 0.0;
  if (best > 0 && best + 1 < num_steps) {
    const double curvature = ssd[best - 1] - 2.0 * ssd[best] + ssd[best + 1];
    if (curvature > 1e-12) {
      offset = std::clamp(0.5 * (ssd[best - 1] - ssd[best + 1]) / curvature, -0.5, 0.5);
    }
  }
  const Eigen::Vector2d match = start + (best + offset) * direction;
  const double idepth = geometry.IdepthFromCurPixel(pixel_in_ref, match, direction);
  if (!std::isfinite(idepth) || idepth < 0.0) return StereoStatus::kOutside;
  Eigen::Vector2d check;
  if (!geometry.Project(pixel_in_ref, idepth, &check)) return StereoStatus::kOutside;
  const double jacobian_sq = geometry.IdepthJacobian(pixel_in_ref, idepth).squaredNorm();
  if (!(jacobian_sq > 1e-12)) return StereoStatus::kBadGeometry;
  // The photometric disparity error with sigma_I^2 raised, if options.residual_intensity_noise,
  // to this match's residual variance SSD / (2 (5 - 1)) (two noisy images, five samples, one
  // fitted position): a match the noise model does not explain gets a wider variance.
  const double residual_ssd = PatchSsd(current, patch, match);
  const double sigma_intensity =
      options.residual_intensity_noise
          ? std::max(options.sigma_intensity, std::sqrt(residual_ssd / 8.0))
          : options.sigma_intensity;
  // The epipolar line's position error: the constant sigma_epipolar_px plus, with a tracked
  // pose covariance, its propagation to this point (EpipolarGeometry::PoseOffsetVar).
  const double epipolar_var = options.sigma_epipolar_px * options.sigma_epipolar_px +
                              geometry.PoseOffsetVar(pixel_in_ref, idepth, normal);
  const double disparity_var = GeometricDisparityVar(patch, epipolar_var) +
                               PhotometricDisparityVar(current, patch, match, sigma_intensity);
  if (!std::isfinite(disparity_var)) return StereoStatus::kOutside;
  double idepth_var = disparity_var / jacobian_sq;  // alpha^2 sigma_lambda^2
  if (options.ssd_ambiguity_variance) {
    // Each other local SSD minimum k is the match with likelihood ratio
    // exp(-(SSD_k - SSD_best) / (4 sigma_I^2)) (difference of two images of noise sigma_I);
    // the variance gets the weighted spread sum w_k (d_k - d)^2 / (1 + sum w_k).
    const double inv_scale = 1.0 / (4.0 * sigma_intensity * sigma_intensity);
    double weight_sum = 1.0, spread = 0.0;
    for (int k = 1; k + 1 < num_steps; ++k) {
      if (std::abs(k - best) <= near_best || ssd[k] > ssd[k - 1] || ssd[k] > ssd[k + 1]) continue;
      const double w = std::exp(-(ssd[k] - ssd[best]) * inv_scale);
      if (w < 1e-4) continue;
      const double d_k =
          geometry.IdepthFromCurPixel(pixel_in_ref, start + k * direction, direction);
      if (!std::isfinite(d_k)) continue;
      spread += w * (d_k - idepth) * (d_k - idepth);
      weight_sum += w;
    }
    idepth_var += spread / weight_sum;
  }
  observation->idepth = idepth;
  observation->disparity_var = disparity_var;
  observation->idepth_var = idepth_var;
  observation->pixel_in_cur = match;
  observation->ssd = residual_ssd;
  return StereoStatus::kOk;
}

}  // namespace pldvo
