#include "residuals/weighting.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/random_draws.h"
#include "core/statistics.h"
#include "tests/residuals/residual_test_utils.h"

namespace pldvo {
namespace {

// Collects the names VisitFields exposes (the config keys).
struct NameCollector {
  std::set<std::string> names;
  template <typename T>
  void Field(const std::string& name, T*, const std::string& doc) {
    EXPECT_FALSE(doc.empty()) << name;
    names.insert(name);
  }
  template <typename Enum>
  void Choice(const std::string& name, Enum*, const ChoiceNames<Enum>& choices,
              const std::string& doc) {
    EXPECT_FALSE(doc.empty()) << name;
    EXPECT_FALSE(choices.empty()) << name;
    names.insert(name);
  }
};

TEST(WeightingOptions, FieldsAndDefaults) {
  WeightingOptions options;
  NameCollector collector;
  options.VisitFields(collector);
  EXPECT_EQ(collector.names, (std::set<std::string>{
                                 "policy", "sigma_intensity", "line_sigma_px", "fixed_ratio_lambda",
                                 "line_error_model", "edge_pixel_sigma_px", "robust_loss",
                                 "robust_threshold", "intensity_noise", "line_noise"}));
  EXPECT_EQ(options.Check(), "");
  EXPECT_EQ(options.intensity_noise, NoiseSource::kFixed);
  EXPECT_EQ(options.line_noise, NoiseSource::kFixed);
  EXPECT_EQ(options.policy, WeightingPolicy::kCovariance);
  EXPECT_EQ(WeightingPolicyNames().size(), 5u);
  options.sigma_intensity = 0.0;
  options.fixed_ratio_lambda = -1.0;
  const std::string error = options.Check();
  EXPECT_NE(error.find("sigma_intensity"), std::string::npos);
  EXPECT_NE(error.find("fixed_ratio_lambda"), std::string::npos);
  EXPECT_EQ(options.line_error_model, LineErrorModel::kPerPixel);
  WeightingOptions shared;
  shared.line_error_model = LineErrorModel::kSharedPerEdge;
  EXPECT_EQ(shared.Check(), "");
  shared.policy = WeightingPolicy::kUniform;
  EXPECT_NE(shared.Check().find("line_error_model"), std::string::npos);
}

TEST(WeightingOptions, LossFunctions) {
  WeightingOptions options;
  options.robust_threshold = 2.0;
  options.robust_loss = RobustLossKind::kNone;
  EXPECT_EQ(MakeLossFunction(options), nullptr);
  options.robust_loss = RobustLossKind::kHuber;
  double rho[3];
  MakeLossFunction(options)->Evaluate(9.0, rho);  // |r| = 3 > 2: linear zone
  EXPECT_DOUBLE_EQ(rho[0], 2.0 * 2.0 * 3.0 - 4.0);
  options.robust_loss = RobustLossKind::kCauchy;
  MakeLossFunction(options)->Evaluate(9.0, rho);
  EXPECT_NEAR(rho[0], 4.0 * std::log1p(9.0 / 4.0), 1e-12);
}

// The expected weights are written out from the formulas with these numbers, not computed with
// the functions under test:
//   photometric (eq. 5): Sigma_f = 2 sigma_I^2 + (g^T J)^2 V with g = (12, -5), J = (20, -8),
//     V = 1e-3: g^T J = 240 + 40 = 280, Sigma_f = 2 * 9 + 78400e-3 = 96.4;
//   point-to-line (eq. 6): Sigma_g = l^T Sigma_x l + x^T Sigma_l x. The line through (10, 10)
//     and (60, 30) has the unit normal (-20, 50) / sqrt(2900); Sigma_x = V J J^T, so
//     l^T Sigma_x l = 1e-3 (-20 * 20 + 50 * -8)^2 / 2900 = 0.64 / 2.9. For endpoints with
//     N(0, sigma^2 I) noise a point's distance to the line moves by (1 - t) e1 + t e2 (e1, e2
//     the endpoints' perpendicular errors, t the position of its foot on the segment), so
//     x^T Sigma_l x = sigma^2 ((1 - t)^2 + t^2); for x = (40, 25), t = (30 * 50 + 15 * 20) / 2900
//     = 18 / 29, giving (11^2 + 18^2) / 29^2 = 445 / 841.
TEST(Weighting, PoliciesFromCovarianceInputs) {
  const Eigen::Vector2d gradient(12.0, -5.0), idepth_jacobian(20.0, -8.0);
  constexpr double kIdepthVar = 1e-3;
  const LineWithCovariance line = FitLine(Eigen::Vector2d(10, 10), Eigen::Vector2d(60, 30), 1.0);
  const Eigen::Vector2d pixel(40.0, 25.0);
  const Eigen::Matrix3d pixel_cov = ReprojectedPixelCovariance(idepth_jacobian, kIdepthVar);

  WeightingOptions options;
  options.sigma_intensity = 3.0;
  options.line_sigma_px = 1.0;
  options.fixed_ratio_lambda = 4.0;
  const double photometric_cov = 1.0 / std::sqrt(96.4);
  const double line_cov = 1.0 / std::sqrt(0.64 / 2.9 + 445.0 / 841.0);
  struct Expected {
    WeightingPolicy policy;
    double photometric;
    double line;
  };
  for (const Expected& e : {Expected{WeightingPolicy::kCovariance, photometric_cov, line_cov},
                            Expected{WeightingPolicy::kUniform, 1.0, 1.0},
                            Expected{WeightingPolicy::kFixedRatio, 1.0 / 3.0, 2.0},
                            Expected{WeightingPolicy::kPhotometricOnly, photometric_cov, 0.0},
                            Expected{WeightingPolicy::kLineOnly, 0.0, line_cov}}) {
    options.policy = e.policy;
    // Relative 1e-12: the formulas above in another order of floating-point operations.
    EXPECT_NEAR(PhotometricSqrtInfo(options, gradient, idepth_jacobian, kIdepthVar), e.photometric,
                1e-12 * e.photometric);
    EXPECT_NEAR(LineSqrtInfo(options, line, pixel, pixel_cov), e.line, 1e-12 * e.line);
    EXPECT_EQ(UsesPhotometric(e.policy), e.photometric != 0.0);
    EXPECT_EQ(UsesLines(e.policy), e.line != 0.0);
  }
}

TEST(Weighting, GeometryConvenienceMatchesComposition) {
  const PinholeCamera camera = testing_utils::TestCamera();
  const ImagePyramid pyramid(testing_utils::SampleImage(camera, testing_utils::SmoothIntensity), 1);
  const SE3 cur_from_ref = testing_utils::TestCurFromRef();
  const Eigen::Vector2d pixel_in_ref(70.0, 50.0);
  constexpr double kIdepth = 0.4, kIdepthVar = 4e-4;
  const WeightingOptions options;

  Eigen::Vector2d pixel_cur;
  ASSERT_TRUE(Reproject(camera, cur_from_ref, pixel_in_ref, kIdepth, &pixel_cur));
  const Eigen::Vector3f sample = pyramid.Sample(0, pixel_cur.x(), pixel_cur.y());
  const Eigen::Vector2d jacobian =
      ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, kIdepth);
  EXPECT_DOUBLE_EQ(
      PhotometricSqrtInfo(options, camera, pyramid, 0, cur_from_ref, pixel_in_ref, kIdepth,
                          kIdepthVar),
      PhotometricSqrtInfo(options, Eigen::Vector2d(sample[1], sample[2]), jacobian, kIdepthVar));
  const LineWithCovariance line =
      FitLine(pixel_cur + Eigen::Vector2d(-20, 3), pixel_cur + Eigen::Vector2d(20, 5), 1.0);
  EXPECT_DOUBLE_EQ(
      LineSqrtInfo(options, camera, cur_from_ref, pixel_in_ref, kIdepth, kIdepthVar, line),
      LineSqrtInfo(options, line, pixel_cur, ReprojectedPixelCovariance(jacobian, kIdepthVar)));
  // Out of the image: no information.
  EXPECT_EQ(PhotometricSqrtInfo(options, camera, pyramid, 0, cur_from_ref,
                                Eigen::Vector2d(-200.0, 50.0), kIdepth, kIdepthVar),
            0.0);
}

// Monte Carlo of one edge: N pixels x_j on a segment, the detected line fitted to endpoints with
// N(0, sigma^2 I) noise (FitLine, shared by every pixel) and an independent point error of
// variance s_j per pixel, g_j = l'^T x_j + sqrt(s_j) z_j. SharedLineErrorWeights must whiten g
// to identity covariance; the per-pixel model (eq. 6: each row alone, 1 / sqrt(s_j + x^T Sigma_l
// x)) gets each row's variance right but leaves the rows strongly correlated, so it counts the
// one line error once per pixel.
TEST(Weighting, SharedLineErrorWhitensTheRowsOfAnEdge) {
  constexpr int kPixels = 40;
  constexpr int kSamples = 20000;
  constexpr double kSigma = 1.0;
  const Eigen::Vector2d p1(80.0, 200.0), p2(380.0, 260.0);
  const LineWithCovariance nominal = FitLine(p1, p2, kSigma);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> point_var(0.02, 0.3);
  std::vector<Eigen::Vector2d> pixels(kPixels);
  std::vector<double> variances(kPixels);
  for (int j = 0; j < kPixels; ++j) {
    pixels[j] = p1 + (j + 0.5) / kPixels * (p2 - p1);  // on the line
    variances[j] = point_var(rng);
  }
  const EdgeLineWeights weights = SharedLineErrorWeights(nominal, pixels, variances);
  const Eigen::MatrixXd whitening =
      (Eigen::MatrixXd::Identity(kPixels, kPixels) -
       weights.shared.v * weights.shared.m * weights.shared.v.transpose()) *
      Eigen::Map<const Eigen::VectorXd>(weights.sqrt_info.data(), kPixels).asDiagonal();
  Eigen::VectorXd per_pixel(kPixels);
  for (int j = 0; j < kPixels; ++j) {
    per_pixel[j] = 1.0 / std::sqrt(variances[j] + pixels[j].homogeneous().dot(
                                                      nominal.cov * pixels[j].homogeneous()));
  }

  std::normal_distribution<double> normal;
  Eigen::MatrixXd shared_cov = Eigen::MatrixXd::Zero(kPixels, kPixels);
  Eigen::MatrixXd per_pixel_cov = Eigen::MatrixXd::Zero(kPixels, kPixels);
  Eigen::VectorXd g(kPixels);
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector2d q1 = p1 + kSigma * DrawVector2(normal, rng);
    const Eigen::Vector2d q2 = p2 + kSigma * DrawVector2(normal, rng);
    const Eigen::Vector3d detected = FitLine(q1, q2, kSigma).line;
    // FitLine's sign convention follows the endpoint order, which the noise does not flip here.
    for (int j = 0; j < kPixels; ++j) {
      g[j] = detected.dot(pixels[j].homogeneous()) + std::sqrt(variances[j]) * normal(rng);
    }
    const Eigen::VectorXd w = whitening * g;
    const Eigen::VectorXd u = per_pixel.cwiseProduct(g);
    shared_cov += w * w.transpose() / kSamples;
    per_pixel_cov += u * u.transpose() / kSamples;
  }
  // Each entry of a 20000-sample covariance has a standard error of ~0.007 (0.01 on the
  // diagonal); 0.05 is > 5 of them.
  EXPECT_LT((shared_cov - Eigen::MatrixXd::Identity(kPixels, kPixels)).cwiseAbs().maxCoeff(), 0.05);
  // Per pixel: each row alone has variance 1 (eq. 6 is right row by row) ...
  EXPECT_LT((per_pixel_cov.diagonal().array() - 1.0).abs().maxCoeff(), 0.05);
  // ... but neighbouring rows share the line error: correlations far from 0.
  double mean_correlation = 0.0;
  for (int i = 0; i < kPixels; ++i) {
    for (int j = 0; j < kPixels; ++j) {
      if (i != j) mean_correlation += per_pixel_cov(i, j) / (kPixels * (kPixels - 1));
    }
  }
  EXPECT_GT(mean_correlation, 0.3);
  std::printf("per-pixel model: mean row correlation %.3f\n", mean_correlation);
}

}  // namespace
}  // namespace pldvo

namespace pldvo {
namespace {

// Errors drawn with variance k sigma^2 + D_i: D_i spread over [0, 3 k sigma^2], as the depth
// term of eq. 5 spreads over a keyframe's points.
struct NoiseSample {
  std::vector<double> errors;
  std::vector<double> other_variances;
};
NoiseSample DrawErrors(double sigma, double noise_factor, int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> depth_part(0.0, 3.0 * noise_factor * sigma * sigma);
  std::normal_distribution<double> unit(0.0, 1.0);
  NoiseSample sample;
  for (int i = 0; i < rows; ++i) {
    const double other = depth_part(rng);
    sample.other_variances.push_back(other);
    sample.errors.push_back(std::sqrt(noise_factor * sigma * sigma + other) * unit(rng));
  }
  return sample;
}

TEST(IntensityNoise, RecoversTheImageNoiseUnderADepthTerm) {
  for (const double sigma : {1.5, 4.0, 12.0}) {
    const NoiseSample sample = DrawErrors(sigma, 2.0, 20000, 7);
    // The MAD of n Gaussian draws has a relative standard deviation of about 1.17 / sqrt(n)
    // (0.8% here); 3% is about 4 of those.
    EXPECT_NEAR(EstimateIntensityNoiseSigma(sample.errors, sample.other_variances, 2.0), sigma,
                0.03 * sigma);
  }
}

TEST(IntensityNoise, ScalesWithContrastSoTheWeightRatioDoesNot) {
  const NoiseSample sample = DrawErrors(4.0, 2.0, 4000, 11);
  const double sigma = EstimateIntensityNoiseSigma(sample.errors, sample.other_variances, 2.0);
  ASSERT_GT(sigma, 0.0);
  const Eigen::Vector2d gradient(30.0, -12.0), idepth_jacobian(40.0, 5.0);
  // A depth part (g^T J_d)^2 V of 13 gray levels^2 against 2 sigma_I^2 of about 32.
  const double idepth_var = 1e-5;
  const LineWithCovariance line = FitLine({10.0, 20.0}, {200.0, 60.0}, 1.0);
  WeightingOptions options;
  options.sigma_intensity = sigma;
  const Eigen::Matrix3d pixel_cov = Eigen::Vector3d(0.1, 0.1, 0.0).asDiagonal();
  const double photometric = PhotometricSqrtInfo(options, gradient, idepth_jacobian, idepth_var);
  const double line_weight = LineSqrtInfo(options, line, {100.0, 40.0}, pixel_cov);
  for (const double contrast : {0.5, 0.75, 1.25}) {
    // The image scaled by c: errors and gradients by c, so the depth part by c^2.
    NoiseSample scaled = sample;
    for (double& e : scaled.errors) e *= contrast;
    for (double& d : scaled.other_variances) d *= contrast * contrast;
    const double scaled_sigma =
        EstimateIntensityNoiseSigma(scaled.errors, scaled.other_variances, 2.0);
    EXPECT_NEAR(scaled_sigma, contrast * sigma, 1e-9 * sigma) << "contrast " << contrast;
    WeightingOptions scaled_options = options;
    scaled_options.sigma_intensity = scaled_sigma;
    // A photometric row's whitened residual, sqrt_info * e, is unchanged; the line rows'
    // weights (pixels) are unchanged: so is their ratio.
    const double scaled_photometric =
        PhotometricSqrtInfo(scaled_options, contrast * gradient, idepth_jacobian, idepth_var);
    EXPECT_NEAR(scaled_photometric * contrast, photometric, 1e-9 * photometric);
    EXPECT_EQ(LineSqrtInfo(scaled_options, line, {100.0, 40.0}, pixel_cov), line_weight);
    // With the fixed sigma_I the ratio moves with the contrast (what the estimate removes).
    const double fixed_photometric =
        PhotometricSqrtInfo(options, contrast * gradient, idepth_jacobian, idepth_var);
    EXPECT_GT(std::abs(fixed_photometric * contrast - photometric), 0.05 * photometric);
  }
}

TEST(IntensityNoise, IsTheRootOfTheRobustScaleEquation) {
  // sigma solves 1.4826 median(|e_i| / sqrt(k sigma^2 + D_i)) = 1; the reference root is a
  // plain bisection in log sigma to a relative bracket of 1e-14.
  for (const unsigned seed : {1u, 2u, 3u}) {
    for (const int rows : {kMinIntensityNoiseRows, 301, 4000}) {
      const NoiseSample sample = DrawErrors(5.0, 2.0, rows, seed);
      const auto scale = [&](double sigma) {
        std::vector<double> whitened;
        for (int i = 0; i < rows; ++i) {
          whitened.push_back(std::abs(sample.errors[i]) /
                             std::sqrt(2.0 * sigma * sigma + sample.other_variances[i]));
        }
        return 1.4826 * Median(whitened);
      };
      double low = 1e-3, high = 1e3;
      ASSERT_GT(scale(low), 1.0);
      ASSERT_LT(scale(high), 1.0);
      while (std::log(high / low) > 1e-14) {
        const double mid = std::sqrt(low * high);
        (scale(mid) > 1.0 ? low : high) = mid;
      }
      EXPECT_NEAR(EstimateIntensityNoiseSigma(sample.errors, sample.other_variances, 2.0), low,
                  1e-11 * low)
          << "seed " << seed << ", rows " << rows;
    }
  }
}

TEST(IntensityNoise, FloorWhenTheDepthTermExplainsTheErrors) {
  // Errors of exactly the depth part's size: no room for image noise.
  std::vector<double> errors, other_variances;
  for (int i = 0; i < 200; ++i) {
    errors.push_back(i % 2 == 0 ? 3.0 : -3.0);
    other_variances.push_back(100.0);
  }
  const double s0 = 1.4826 * 3.0 / std::sqrt(2.0);
  EXPECT_DOUBLE_EQ(EstimateIntensityNoiseSigma(errors, other_variances, 2.0),
                   kIntensityNoiseFloorFraction * s0);
}

// Point-to-line errors g_j with variance s^2 L_j + D_j: L_j the frontend's line part (varying
// along and between lines), D_j the depth part (up to 1.5 s^2: where it dominates, the errors
// hardly tell s).
NoiseSample DrawLineErrors(double scale, int rows, unsigned seed,
                           std::vector<double>* line_variances) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> line_part(0.05, 2.0), depth_part(0.0, 1.5 * scale * scale);
  std::normal_distribution<double> unit(0.0, 1.0);
  NoiseSample sample;
  for (int j = 0; j < rows; ++j) {
    const double line = line_part(rng), depth = depth_part(rng);
    line_variances->push_back(line);
    sample.other_variances.push_back(depth);
    sample.errors.push_back(std::sqrt(scale * scale * line + depth) * unit(rng));
  }
  return sample;
}

TEST(LineNoise, RecoversTheLineCovarianceScaleUnderADepthTerm) {
  for (const double scale : {0.5, 1.0, 2.5}) {
    std::vector<double> line_variances;
    const NoiseSample sample = DrawLineErrors(scale, 20000, 5, &line_variances);
    // The MAD's relative sd (0.8% here) over the line part's share of the variance (about 0.6):
    // s scatters by 1.3% (12 draws of this sample); 5% is about 4 of those.
    EXPECT_NEAR(EstimateLineNoiseScale(sample.errors, sample.other_variances, line_variances),
                scale, 0.05 * scale);
  }
}

TEST(LineNoise, LineWeightsDoNotDependOnTheAssumedEndpointSigma) {
  // A frontend that assumes endpoint sigmas c times larger (every L_j times c^2) gets s / c: the
  // rows' variances s^2 L_j + D_j, and so their weights, are the same.
  std::vector<double> line_variances;
  const NoiseSample sample = DrawLineErrors(1.7, 3000, 9, &line_variances);
  const double scale =
      EstimateLineNoiseScale(sample.errors, sample.other_variances, line_variances);
  ASSERT_GT(scale, 0.0);
  for (const double c : {0.25, 2.0, 8.0}) {
    std::vector<double> assumed = line_variances;
    for (double& l : assumed) l *= c * c;
    EXPECT_NEAR(EstimateLineNoiseScale(sample.errors, sample.other_variances, assumed), scale / c,
                1e-9 * scale / c)
        << "c " << c;
  }
  // A row without a line part is left out; mismatched sizes give no estimate.
  std::vector<double> broken = line_variances;
  broken[7] = 0.0;
  std::vector<double> errors = sample.errors, depth = sample.other_variances, line = line_variances;
  for (auto* v : {&errors, &depth, &line}) v->erase(v->begin() + 7);
  EXPECT_EQ(EstimateLineNoiseScale(sample.errors, sample.other_variances, broken),
            EstimateLineNoiseScale(errors, depth, line));
  std::vector<double> shorter = line_variances;
  shorter.pop_back();
  EXPECT_EQ(EstimateLineNoiseScale(sample.errors, sample.other_variances, shorter), 0.0);
}

TEST(IntensityNoise, NoEstimateWithoutEnoughRowsOrImageNoise) {
  const NoiseSample sample = DrawErrors(4.0, 2.0, kMinIntensityNoiseRows - 1, 3);
  EXPECT_EQ(EstimateIntensityNoiseSigma(sample.errors, sample.other_variances, 2.0), 0.0);
  const NoiseSample enough = DrawErrors(4.0, 2.0, kMinIntensityNoiseRows, 3);
  EXPECT_GT(EstimateIntensityNoiseSigma(enough.errors, enough.other_variances, 2.0), 0.0);
  EXPECT_EQ(EstimateIntensityNoiseSigma(enough.errors, enough.other_variances, 0.0), 0.0);
  EXPECT_EQ(IntensityNoiseFactor(WeightingPolicy::kCovariance), 2.0);
  EXPECT_EQ(IntensityNoiseFactor(WeightingPolicy::kFixedRatio), 1.0);
  EXPECT_EQ(IntensityNoiseFactor(WeightingPolicy::kUniform), 0.0);
}

}  // namespace
}  // namespace pldvo
