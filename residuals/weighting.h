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
#ifndef PLDVO_RESIDUALS_WEIGHTING_H_
#define PLDVO_RESIDUALS_WEIGHTING_H_

#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <memory>
#include <string>

#include "core/image_pyramid.h"
#include "core/options.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/covariance_models.h"

namespace pldvo {

enum class WeightingPolicy { kCovariance, kUniform, kFixedRatio, kPhotometricOnly, kLineOnly };
enum class RobustLossKind { kNone, kHuber, kCauchy };

inline const ChoiceNames<WeightingPolicy>& WeightingPolicyNames() {
  static const ChoiceNames<WeightingPolicy> names = {
      {"covariance", WeightingPolicy::kCovariance},
      {"uniform", WeightingPolicy::kUniform},
      {"fixed_ratio", WeightingPolicy::kFixedRatio},
      {"photometric_only", WeightingPolicy::kPhotometricOnly},
      {"line_only", WeightingPolicy::kLineOnly}};
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
  // Line endpoint noise at pyramid level 0, pixels (isotropic); at level k it is
  // line_sigma_px / 2^k, see LineSigmaAtLevel.
  double line_sigma_px = 1.0;
  // lambda of "fixed_ratio": line cost weight relative to the photometric one.
  double fixed_ratio_lambda = 1.0;
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
    v.Field("line_sigma_px", &line_sigma_px,
            "Line endpoint noise in pixels at full resolution (isotropic).");
    v.Field("fixed_ratio_lambda", &fixed_ratio_lambda,
            "Weight of the line cost relative to the photometric cost for policy fixed_ratio.");
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

// Line endpoint sigma at a pyramid level (each level halves the pixel coordinates).
double LineSigmaAtLevel(const WeightingOptions& options, int level);

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
// its covariance (FitLine at the level's pixels and LineSigmaAtLevel), the reprojected pixel
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
