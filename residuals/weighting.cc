#include "residuals/weighting.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/statistics.h"

namespace pldvo {
namespace {

bool PositiveFinite(double value) { return value > 0.0 && std::isfinite(value); }

// 1 / sqrt(var), 0 for a non-positive or non-finite variance (no information).
double InverseSqrt(double var) { return PositiveFinite(var) ? 1.0 / std::sqrt(var) : 0.0; }

}  // namespace

std::string WeightingOptions::Check() const {
  std::ostringstream error;
  if (!PositiveFinite(sigma_intensity)) {
    error << "sigma_intensity must be positive and finite, got " << sigma_intensity << "; ";
  }
  if (!PositiveFinite(line_sigma_px)) {
    error << "line_sigma_px must be positive and finite, got " << line_sigma_px << "; ";
  }
  if (!(fixed_ratio_lambda >= 0.0) || !std::isfinite(fixed_ratio_lambda)) {
    error << "fixed_ratio_lambda must be >= 0 and finite, got " << fixed_ratio_lambda << "; ";
  }
  if (!(edge_pixel_sigma_px >= 0.0) || !std::isfinite(edge_pixel_sigma_px)) {
    error << "edge_pixel_sigma_px must be >= 0 and finite, got " << edge_pixel_sigma_px << "; ";
  }
  if (line_error_model == LineErrorModel::kSharedPerEdge &&
      (policy == WeightingPolicy::kUniform || policy == WeightingPolicy::kFixedRatio)) {
    error << "line_error_model shared_per_edge needs a covariance policy (covariance, line_only); ";
  }
  if (robust_loss != RobustLossKind::kNone && !PositiveFinite(robust_threshold)) {
    error << "robust_threshold must be positive and finite, got " << robust_threshold << "; ";
  }
  return error.str();
}

double IntensityNoiseFactor(WeightingPolicy policy) {
  switch (policy) {
    case WeightingPolicy::kCovariance:
    case WeightingPolicy::kPhotometricOnly:
      return 2.0;
    case WeightingPolicy::kFixedRatio:
      return 1.0;
    case WeightingPolicy::kUniform:
    case WeightingPolicy::kLineOnly:
      return 0.0;
  }
  return 0.0;
}

double IntensityNoiseSigma(const WeightingOptions& options, double estimate) {
  return options.intensity_noise == NoiseSource::kEstimated && estimate > 0.0
             ? estimate
             : options.sigma_intensity;
}

double EstimateIntensityNoiseSigma(const std::vector<double>& errors,
                                   const std::vector<double>& other_variances,
                                   double noise_factor) {
  const size_t rows = errors.size();
  if (rows < static_cast<size_t>(kMinIntensityNoiseRows) || other_variances.size() != rows ||
      !(noise_factor > 0.0)) {
    return 0.0;
  }
  constexpr double kMadToSigma = 1.4826;
  std::vector<double> whitened(rows);
  for (size_t i = 0; i < rows; ++i) whitened[i] = std::abs(errors[i]);
  const double s0 = kMadToSigma * Median(whitened) / std::sqrt(noise_factor);
  if (!(s0 > 0.0) || !std::isfinite(s0)) return 0.0;
  // Robust scale of the whitened errors at sigma; decreasing in sigma, <= 1 at s0.
  const auto scale = [&](double sigma) {
    for (size_t i = 0; i < rows; ++i) {
      whitened[i] = std::abs(errors[i]) /
                    std::sqrt(noise_factor * sigma * sigma + std::max(other_variances[i], 0.0));
    }
    return kMadToSigma * Median(whitened);
  };
  const double low = kIntensityNoiseFloorFraction * s0;
  const double excess_low = scale(low) - 1.0;
  if (excess_low <= 0.0) return low;
  // scale(sigma) = 1 in x = log sigma on [log low, log s0] (excess > 0 at a, <= 0 at b): regula
  // falsi with the Illinois modification, which keeps both ends moving. The median of smooth
  // functions is piecewise smooth, so it converges superlinearly: far fewer medians than the 40
  // of bisection, to the same relative bracket of 1e-12.
  double a = std::log(low), b = std::log(s0);
  double excess_a = excess_low, excess_b = scale(s0) - 1.0;
  int kept_side = 0;  // +1: a was kept by the last step, -1: b was
  for (int iteration = 0; iteration < 200 && b - a > 1e-12; ++iteration) {
    double x = (a * excess_b - b * excess_a) / (excess_b - excess_a);
    if (!(x > a && x < b)) x = 0.5 * (a + b);
    const double excess = scale(std::exp(x)) - 1.0;
    if (excess > 0.0) {
      a = x;
      excess_a = excess;
      if (kept_side == -1) excess_b *= 0.5;
      kept_side = -1;
    } else {
      b = x;
      excess_b = excess;
      if (kept_side == 1) excess_a *= 0.5;
      kept_side = 1;
    }
  }
  return std::exp(0.5 * (a + b));
}

double EstimateLineNoiseScale(const std::vector<double>& errors,
                              const std::vector<double>& depth_variances,
                              const std::vector<double>& line_variances) {
  const size_t rows = errors.size();
  if (depth_variances.size() != rows || line_variances.size() != rows) return 0.0;
  std::vector<double> normalized_errors, normalized_depth_variances;
  normalized_errors.reserve(rows);
  normalized_depth_variances.reserve(rows);
  for (size_t j = 0; j < rows; ++j) {
    if (!(line_variances[j] > 0.0)) continue;
    normalized_errors.push_back(errors[j] / std::sqrt(line_variances[j]));
    normalized_depth_variances.push_back(depth_variances[j] / line_variances[j]);
  }
  return EstimateIntensityNoiseSigma(normalized_errors, normalized_depth_variances, 1.0);
}

EdgeLineWeights SharedLineErrorWeights(const LineWithCovariance& line_in_cur,
                                       const std::vector<Eigen::Vector2d>& pixels_cur,
                                       const std::vector<double>& point_variances) {
  const int n = static_cast<int>(pixels_cur.size());
  EdgeLineWeights weights;
  weights.sqrt_info.resize(n);
  weights.shared.v.resize(n, 2);
  const Eigen::Matrix<double, 3, 2> factor = LineCovarianceFactor(line_in_cur.cov);
  for (int j = 0; j < n; ++j) {
    weights.sqrt_info[j] = 1.0 / std::sqrt(std::max(point_variances[j], kMinPointLineVariance));
    weights.shared.v.row(j) =
        weights.sqrt_info[j] * (pixels_cur[j].homogeneous().transpose() * factor);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> gram(weights.shared.v.transpose() *
                                                            weights.shared.v);
  Eigen::Vector2d f;
  for (int k = 0; k < 2; ++k) {
    const double s = std::max(gram.eigenvalues()[k], 0.0);
    // (1 - 1/sqrt(1 + s)) / s = 1 / (sqrt(1 + s) (1 + sqrt(1 + s))), finite at s = 0.
    const double root = std::sqrt(1.0 + s);
    f[k] = 1.0 / (root * (1.0 + root));
  }
  weights.shared.m = gram.eigenvectors() * f.asDiagonal() * gram.eigenvectors().transpose();
  return weights;
}

std::unique_ptr<ceres::LossFunction> MakeLossFunction(const WeightingOptions& options) {
  switch (options.robust_loss) {
    case RobustLossKind::kNone:
      return nullptr;
    case RobustLossKind::kHuber:
      return std::make_unique<ceres::HuberLoss>(options.robust_threshold);
    case RobustLossKind::kCauchy:
      return std::make_unique<ceres::CauchyLoss>(options.robust_threshold);
  }
  return nullptr;
}

double PhotometricSqrtInfo(const WeightingOptions& options, const Eigen::Vector2d& gradient_cur,
                           const Eigen::Vector2d& pixel_idepth_jacobian, double idepth_var) {
  switch (options.policy) {
    case WeightingPolicy::kCovariance:
    case WeightingPolicy::kPhotometricOnly:
      return InverseSqrt(PhotometricVariance(options.sigma_intensity, gradient_cur,
                                             pixel_idepth_jacobian, idepth_var));
    case WeightingPolicy::kUniform:
      return 1.0;
    case WeightingPolicy::kFixedRatio:
      return 1.0 / options.sigma_intensity;
    case WeightingPolicy::kLineOnly:
      return 0.0;
  }
  return 0.0;
}

double PhotometricSqrtInfo(const WeightingOptions& options, const PinholeCamera& camera,
                           const ImagePyramid& cur_pyramid, int level, const SE3& cur_from_ref,
                           const Eigen::Vector2d& pixel_in_ref, double idepth, double idepth_var) {
  Eigen::Vector2d pixel_cur;
  if (!Reproject(camera, cur_from_ref, pixel_in_ref, idepth, &pixel_cur)) return 0.0;
  // Same sampling area as PhotometricResidual.
  if (!(pixel_cur.x() >= 1.0 && pixel_cur.y() >= 1.0 && pixel_cur.x() < camera.width - 2 &&
        pixel_cur.y() < camera.height - 2)) {
    return 0.0;
  }
  const Eigen::Vector3f sample = cur_pyramid.Sample(level, pixel_cur.x(), pixel_cur.y());
  const Eigen::Vector2d gradient(sample[1], sample[2]);
  return PhotometricSqrtInfo(options, gradient,
                             ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, idepth),
                             idepth_var);
}

double LineSqrtInfo(const WeightingOptions& options, const LineWithCovariance& line_in_cur,
                    const Eigen::Vector2d& pixel_cur, const Eigen::Matrix3d& pixel_cov) {
  switch (options.policy) {
    case WeightingPolicy::kCovariance:
    case WeightingPolicy::kLineOnly:
      return InverseSqrt(
          PointToLineVariance(line_in_cur.line, line_in_cur.cov, pixel_cur, pixel_cov));
    case WeightingPolicy::kUniform:
      return 1.0;
    case WeightingPolicy::kFixedRatio:
      return std::sqrt(options.fixed_ratio_lambda) / options.line_sigma_px;
    case WeightingPolicy::kPhotometricOnly:
      return 0.0;
  }
  return 0.0;
}

double LineSqrtInfo(const WeightingOptions& options, const PinholeCamera& camera,
                    const SE3& cur_from_ref, const Eigen::Vector2d& pixel_in_ref, double idepth,
                    double idepth_var, const LineWithCovariance& line_in_cur) {
  Eigen::Vector2d pixel_cur;
  if (!Reproject(camera, cur_from_ref, pixel_in_ref, idepth, &pixel_cur)) return 0.0;
  return LineSqrtInfo(
      options, line_in_cur, pixel_cur,
      ReprojectedPixelCovariance(camera, cur_from_ref, pixel_in_ref, idepth, idepth_var));
}

}  // namespace pldvo
