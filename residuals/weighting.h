// How the two residual families are weighted against each other (the paper's Sec. IV weights and
// the ablations of it), and the robust loss. The one place that turns covariance models
// (covariance_models.h) into the sqrt_info the cost functions take, so problem builders do not
// duplicate it. All sqrt_info are computed at the linearisation point and held constant inside
// a solve.
//
// Policies (config names in quotes):
//   "covariance"        the paper: photometric sqrt_info = 1 / sqrt(PhotometricVariance),
//                       line sqrt_info = 1 / sqrt(PointToLineVariance).
//   "uniform"           both 1: gray levels and pixels summed unweighted.
//   "fixed_ratio"       photometric 1 / sigma_intensity, line sqrt(lambda) / line_sigma_px:
//                       a constant trade-off lambda between the families, independent of depth
//                       uncertainty and line length (lambda = 1 is "each family whitened by its
//                       raw measurement noise").
//   "photometric_only"  photometric as in "covariance", lines 0 (the builder adds no lines).
//   "line_only"         lines as in "covariance", photometric 0 (the builder adds no pixels).
// line_error_model chooses, for "covariance" and "line_only", whether an edge's pixels count
// its line error Sigma_l independently (the paper) or once (shared_per_edge).
#ifndef PLDVO_RESIDUALS_WEIGHTING_H_
#define PLDVO_RESIDUALS_WEIGHTING_H_

#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "core/image_pyramid.h"
#include "core/options.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/covariance_models.h"
#include "residuals/point_to_line_residual.h"

namespace pldvo {

enum class WeightingPolicy { kCovariance, kUniform, kFixedRatio, kPhotometricOnly, kLineOnly };
enum class RobustLossKind { kNone, kHuber, kCauchy };
enum class LineErrorModel { kPerPixel, kSharedPerEdge };
enum class NoiseSource { kFixed, kEstimated };

inline const ChoiceNames<WeightingPolicy>& WeightingPolicyNames() {
  static const ChoiceNames<WeightingPolicy> names = {
      {"covariance", WeightingPolicy::kCovariance},
      {"uniform", WeightingPolicy::kUniform},
      {"fixed_ratio", WeightingPolicy::kFixedRatio},
      {"photometric_only", WeightingPolicy::kPhotometricOnly},
      {"line_only", WeightingPolicy::kLineOnly}};
  return names;
}
inline const ChoiceNames<LineErrorModel>& LineErrorModelNames() {
  static const ChoiceNames<LineErrorModel> names = {
      {"per_pixel", LineErrorModel::kPerPixel},
      {"shared_per_edge", LineErrorModel::kSharedPerEdge}};
  return names;
}
inline const ChoiceNames<NoiseSource>& NoiseSourceNames() {
  static const ChoiceNames<NoiseSource> names = {{"fixed", NoiseSource::kFixed},
                                                 {"estimated", NoiseSource::kEstimated}};
  return names;
}

inline const ChoiceNames<RobustLossKind>& RobustLossKindNames() {
  static const ChoiceNames<RobustLossKind> names = {{"none", RobustLossKind::kNone},
                                                    {"huber", RobustLossKind::kHuber},
                                                    {"cauchy", RobustLossKind::kCauchy}};
  return names;
}

struct WeightingOptions {
  WeightingPolicy policy = WeightingPolicy::kCovariance;
  // sigma_I: image noise per pixel, gray levels (0..255). 4 is LSD-SLAM's cameraPixelNoise.
  double sigma_intensity = 4.0;
  // Where sigma_I comes from: fixed (sigma_intensity, gray levels: the weights change with the
  // image's contrast while the line weights, in pixels, do not) or estimated (from the previous
  // frame's photometric errors at its solution, EstimateIntensityNoiseSigma: scales with the
  // contrast, so the ratio of photometric to line weights does not; sigma_intensity then only
  // serves the first frame). The windowed BA takes the estimate of the newest tracked frame.
  NoiseSource intensity_noise = NoiseSource::kFixed;
  // Where the scale of a line's covariance Sigma_l (eq. 6) comes from: fixed (as the line
  // frontend fits it, lines.detector.endpoint_sigma_px) or estimated (Sigma_l times s^2, s from
  // the previous frame's point-to-line errors at its solution, EstimateLineNoiseScale: lines
  // noisier than the detector's model, as on low contrast, blur or occlusion edges, weigh less).
  // Tracking only; policies covariance and line_only.
  NoiseSource line_noise = NoiseSource::kFixed;
  // "fixed_ratio" only: the pixel scale of a line row, sqrt_info = sqrt(lambda) / line_sigma_px.
  // (The covariance policies take Sigma_l from the matched segment, which the line frontend
  // fits with lines.detector.endpoint_sigma_px.)
  double line_sigma_px = 1.0;
  // lambda of "fixed_ratio": line cost weight relative to the photometric one.
  double fixed_ratio_lambda = 1.0;
  // How Sigma_l enters Sigma_g (eq. 6) for the policies "covariance" and "line_only":
  //   per_pixel        the paper: every pixel's sigma_g^2 = l^T Sigma_x' l + x'^T Sigma_l x', the
  //                    rows independent (an edge of N pixels counts its line error N times);
  //   shared_per_edge  the pixels of an edge share one line error: Cov(g) = D + X Sigma_l X^T
  //                    with D = diag(l^T Sigma_x'j l), whitened exactly (SharedLineErrorWeights).
  LineErrorModel line_error_model = LineErrorModel::kPerPixel;
  // shared_per_edge only: the independent error of an edge pixel across its line at level 0,
  // px (halved per level), added to each row's depth part: l^T Sigma_x' l + sigma_e^2.
  double edge_pixel_sigma_px = 0.2;
  // Robust loss on every whitened residual row.
  RobustLossKind robust_loss = RobustLossKind::kHuber;
  // Its scale in whitened units (Ceres' `a`: Huber is quadratic for |r| <= a). 1.345 is
  // Huber's 95%-efficiency constant for Gaussian noise.
  double robust_threshold = 1.345;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Choice("policy", &policy, WeightingPolicyNames(),
             "How photometric and point-to-line residuals are weighted: covariance (the paper), "
             "uniform, fixed_ratio, photometric_only, line_only.");
    v.Field("sigma_intensity", &sigma_intensity, "Image noise sigma_I in gray levels.");
    v.Choice(
        "intensity_noise", &intensity_noise, NoiseSourceNames(),
        "Where sigma_I comes from: fixed (sigma_intensity) or estimated (from the previous "
        "frame's photometric errors; contrast-invariant weights; the windowed BA takes the newest "
        "frame's).");
    v.Choice("line_noise", &line_noise, NoiseSourceNames(),
             "Scale of the lines' covariance: fixed (the line frontend's) or estimated (from the "
             "previous frame's point-to-line errors; tracking only).");
    v.Field("line_sigma_px", &line_sigma_px,
            "fixed_ratio only: pixel scale of a line row (covariance policies take Sigma_l from "
            "the segments, lines.detector.endpoint_sigma_px).");
    v.Field("fixed_ratio_lambda", &fixed_ratio_lambda,
            "Weight of the line cost relative to the photometric cost for policy fixed_ratio.");
    v.Choice("line_error_model", &line_error_model, LineErrorModelNames(),
             "How the line covariance enters (policies covariance, line_only): per_pixel (the "
             "paper, eq. 6) or shared_per_edge (one line error for all pixels of an edge).");
    v.Field("edge_pixel_sigma_px", &edge_pixel_sigma_px,
            "shared_per_edge: independent error of an edge pixel across its line, px at level 0.");
    v.Choice("robust_loss", &robust_loss, RobustLossKindNames(),
             "Robust loss on each whitened residual: none, huber, cauchy.");
    v.Field("robust_threshold", &robust_threshold, "Scale of the robust loss in whitened units.");
  }
  // "" when valid, otherwise what is wrong (all sigmas and thresholds positive and finite,
  // lambda >= 0).
  std::string Check() const;
};

// False for the family a policy switches off (the builder then adds no such residuals).
inline bool UsesPhotometric(WeightingPolicy policy) { return policy != WeightingPolicy::kLineOnly; }
inline bool UsesLines(WeightingPolicy policy) {
  return policy != WeightingPolicy::kPhotometricOnly;
}

// Whitening of the rows of one edge under LineErrorModel::kSharedPerEdge: with
// e_j = sqrt_info_j l^T x'_j, sqrt_info_j = 1 / sqrt(max(s_j, kMinPointLineVariance)),
// s_j = point_variances[j] (the builder passes l^T Sigma_x'j l + edge_pixel_sigma^2), and
// V = D^-1/2 X B (rows (x'_j; 1)^T B sqrt_info_j, Sigma_l = B B^T,
// LineCovarianceFactor), r = (I + V V^T)^-1/2 e has identity covariance. With V^T V = P L P^T,
// (I + V V^T)^-1/2 = I - V M V^T, M = P diag(f(l_k)) P^T, f(s) = (1 - 1/sqrt(1 + s)) / s
// (f(0) = 1/2).
struct EdgeLineWeights {
  std::vector<double> sqrt_info;  // per row, the point part D^-1/2
  SharedLineError shared;
};
// Floor of s_j, px^2: (0.01 px)^2, far below any image measurement, keeps D invertible for
// points whose reprojection does not depend on their depth (no translation).
constexpr double kMinPointLineVariance = 1e-4;
EdgeLineWeights SharedLineErrorWeights(const LineWithCovariance& line_in_cur,
                                       const std::vector<Eigen::Vector2d>& pixels_cur,
                                       const std::vector<double>& point_variances);

// The factor k of the image noise in a photometric row's variance k sigma_I^2 + D, D the rest:
// 2 for covariance and photometric_only (eq. 5: the noise of both images), 1 for fixed_ratio,
// 0 where sigma_I does not enter (uniform, line_only).
double IntensityNoiseFactor(WeightingPolicy policy);

// sigma_I of eq. 5 (gray levels): `estimate` (EstimateIntensityNoiseSigma of an earlier
// solution) where options.intensity_noise is estimated and an estimate exists (> 0), otherwise
// options.sigma_intensity.
double IntensityNoiseSigma(const WeightingOptions& options, double estimate);

// The image noise sigma_I (gray levels) that the photometric errors e_i at a solution imply,
// given each row's variance k sigma_I^2 + D_i (k = noise_factor, D_i = other_variances[i], the
// depth part of eq. 5): the sigma at which the whitened errors have unit robust scale,
// 1.4826 median_i |e_i| / sqrt(k sigma^2 + D_i) = 1 (the MAD of a unit Gaussian is 1/1.4826).
// Scaling every e_i by c and every D_i by c^2 (an image scaled in contrast) scales it by c.
// It lies in [kIntensityNoiseFloorFraction s0, s0], s0 = 1.4826 median |e_i| / sqrt(k) (every
// D_i zero); the floor when the depth part alone explains the errors. 0 (no estimate) for
// fewer than kMinIntensityNoiseRows rows, k <= 0 or all errors zero.
double EstimateIntensityNoiseSigma(const std::vector<double>& errors,
                                   const std::vector<double>& other_variances, double noise_factor);
constexpr int kMinIntensityNoiseRows = 50;
constexpr double kIntensityNoiseFloorFraction = 0.25;

// The scale s of the lines' covariance that the point-to-line errors g_j at a solution imply,
// given each row's variance s^2 L_j + D_j (L_j = x'^T Sigma_l x' with the frontend's Sigma_l,
// D_j = l^T Sigma_x' l the depth part of eq. 6): the s at which the whitened errors have unit
// robust scale, 1.4826 median_j |g_j| / sqrt(s^2 L_j + D_j) = 1. The same root as
// EstimateIntensityNoiseSigma of g_j / sqrt(L_j) with depth parts D_j / L_j and k = 1, and the
// same bounds and 0 for no estimate (fewer than kMinIntensityNoiseRows rows with L_j > 0, or
// mismatched sizes).
double EstimateLineNoiseScale(const std::vector<double>& errors,
                              const std::vector<double>& depth_variances,
                              const std::vector<double>& line_variances);

// The robust loss of the options, or nullptr for "none". Pass it to the cost functions (which
// do not own it) or to ceres::Problem (which does, unless told otherwise).
std::unique_ptr<ceres::LossFunction> MakeLossFunction(const WeightingOptions& options);

// Photometric sqrt_info of one pixel from its covariance inputs: the current-image gradient at
// the reprojection and J_d = d tau / d d (covariance_models.h).
double PhotometricSqrtInfo(const WeightingOptions& options, const Eigen::Vector2d& gradient_cur,
                           const Eigen::Vector2d& pixel_idepth_jacobian, double idepth_var);

// The same from the geometry at the linearisation point: reprojects (x, d) with cur_from_ref
// into the level of `cur_pyramid` (camera = camera of that level), samples the gradient there.
// Returns 0 when the reprojection is invalid (behind the camera or not samplable).
double PhotometricSqrtInfo(const WeightingOptions& options, const PinholeCamera& camera,
                           const ImagePyramid& cur_pyramid, int level, const SE3& cur_from_ref,
                           const Eigen::Vector2d& pixel_in_ref, double idepth, double idepth_var);

// Point-to-line sqrt_info of one edge pixel from its covariance inputs: the matched line with
// its covariance (the segment's Sigma_l moved to the level, LineAtLevel), the reprojected pixel
// and its 3x3 covariance (ReprojectedPixelCovariance).
double LineSqrtInfo(const WeightingOptions& options, const LineWithCovariance& line_in_cur,
                    const Eigen::Vector2d& pixel_cur, const Eigen::Matrix3d& pixel_cov);

// The same from the geometry at the linearisation point. Returns 0 when the reprojection is
// behind the camera.
double LineSqrtInfo(const WeightingOptions& options, const PinholeCamera& camera,
                    const SE3& cur_from_ref, const Eigen::Vector2d& pixel_in_ref, double idepth,
                    double idepth_var, const LineWithCovariance& line_in_cur);

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_WEIGHTING_H_
