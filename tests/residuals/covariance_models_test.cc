// Monte Carlo checks of every covariance model: each samples the real nonlinear function
// (cross product + normalisation, actual reprojection with perturbed inverse depth, actual
// image sampling of noisy images through ImagePyramid and PhotometricResidual) and compares the
// sample variance with the first-order model. With 20 000 samples the standard error of a
// sample variance is sqrt(2 / N) = 1%, so the 10% bound is dominated by the model's own
// (first-order) error, which is what is being checked.
#include "residuals/covariance_models.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/random_draws.h"
#include "residuals/photometric_residual.h"
#include "residuals/se3_manifold.h"
#include "tests/residuals/residual_test_utils.h"

namespace pldvo {
namespace {

constexpr int kSamples = 20000;
constexpr double kModelTolerance = 0.10;  // the bound

template <int N>
Eigen::Matrix<double, N, N> SampleCovariance(
    const std::vector<Eigen::Matrix<double, N, 1>>& samples) {
  Eigen::Matrix<double, N, 1> mean = Eigen::Matrix<double, N, 1>::Zero();
  for (const auto& s : samples) mean += s;
  mean /= static_cast<double>(samples.size());
  Eigen::Matrix<double, N, N> cov = Eigen::Matrix<double, N, N>::Zero();
  for (const auto& s : samples) cov += (s - mean) * (s - mean).transpose();
  return cov / static_cast<double>(samples.size() - 1);
}

double SampleVariance(const std::vector<double>& samples) {
  std::vector<Eigen::Matrix<double, 1, 1>> wrapped;
  wrapped.reserve(samples.size());
  for (const double s : samples) wrapped.push_back(Eigen::Matrix<double, 1, 1>(s));
  return SampleCovariance<1>(wrapped)(0, 0);
}

// |measured - model| / |model|; also prints the ratio so the test log carries the numbers.
double RelativeError(double measured, double model) {
  std::printf("[ MC ratio ] %s: measured / model = %.4f\n",
              ::testing::UnitTest::GetInstance()->current_test_info()->name(), measured / model);
  return std::abs(measured - model) / std::abs(model);
}

// ------------------------------------------------------------------------------------------
// FitLine.

TEST(FitLine, NormalisedSignedDistance) {
  const LineWithCovariance fit = FitLine(Eigen::Vector2d(10, 20), Eigen::Vector2d(50, 20), 1.0);
  EXPECT_NEAR(fit.line.head<2>().norm(), 1.0, 1e-15);
  // (a, b) = (y1 - y2, x2 - x1) / L = (0, 1): distance = y - 20.
  EXPECT_NEAR(fit.line.dot(Eigen::Vector3d(30, 23, 1)), 3.0, 1e-12);
  EXPECT_THROW(FitLine(Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1), 1.0), std::invalid_argument);
  EXPECT_THROW(FitLine(Eigen::Vector2d(1, 1), Eigen::Vector2d(5, 1), -1.0), std::invalid_argument);
}

TEST(FitLine, CovarianceMatchesMonteCarlo) {
  const Eigen::Vector2d p1(40.0, 30.0), p2(110.0, 75.0);  // 83 px, oblique
  constexpr double kSigmaPx = 1.0;
  const LineWithCovariance model = FitLine(p1, p2, kSigmaPx);
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, kSigmaPx);
  std::vector<Eigen::Vector3d> lines;
  lines.reserve(kSamples);
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector2d q1 = p1 + DrawVector2(noise, rng);
    const Eigen::Vector2d q2 = p2 + DrawVector2(noise, rng);
    lines.push_back(FitLine(q1, q2, 0.0).line);  // the real cross product + normalisation
  }
  const Eigen::Matrix3d measured = SampleCovariance<3>(lines);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(RelativeError(measured(i, i), model.cov(i, i)), kModelTolerance)
        << "entry " << i << " measured " << measured(i, i) << " model " << model.cov(i, i);
  }
  // The quantity the point-to-line model uses: x^T Sigma_l x, at the endpoints, the midpoint,
  // a point beyond the segment and one far off it.
  for (const Eigen::Vector2d& x : {p1, p2, Eigen::Vector2d(0.5 * (p1 + p2)),
                                   Eigen::Vector2d(150.0, 101.0), Eigen::Vector2d(20.0, 110.0)}) {
    const Eigen::Vector3d h(x.x(), x.y(), 1.0);
    EXPECT_LT(RelativeError(h.dot(measured * h), h.dot(model.cov * h)), kModelTolerance)
        << "at " << x.transpose();
  }
}

TEST(FitLine, LongerLinesHaveSmallerCovariance) {
  const Eigen::Vector2d middle(80.0, 60.0);
  const Eigen::Vector2d direction = Eigen::Vector2d(3.0, 1.0).normalized();
  const Eigen::Vector3d probe(middle.x() + 50.0 * direction.x(), middle.y() + 50.0 * direction.y(),
                              1.0);
  double previous_probe_var = std::numeric_limits<double>::infinity();
  for (const double length : {10.0, 20.0, 40.0, 80.0, 160.0}) {
    const LineWithCovariance fit =
        FitLine(middle - 0.5 * length * direction, middle + 0.5 * length * direction, 1.5);
    // Angular variance of the normal: 2 sigma^2 / L^2 (two endpoints, lever arm L).
    EXPECT_NEAR((fit.cov.topLeftCorner<2, 2>().trace()), 2.0 * 1.5 * 1.5 / (length * length),
                1e-12);
    // Distance variance at the midpoint does not depend on length: sigma^2 / 2.
    const Eigen::Vector3d mid(middle.x(), middle.y(), 1.0);
    EXPECT_NEAR(mid.dot(fit.cov * mid), 0.5 * 1.5 * 1.5, 1e-9);
    const double probe_var = probe.dot(fit.cov * probe);
    EXPECT_LT(probe_var, previous_probe_var) << "length " << length;
    previous_probe_var = probe_var;
  }
}

// ------------------------------------------------------------------------------------------
// Reprojected pixel covariance.

TEST(ReprojectedPixelCovariance, MatchesMonteCarlo) {
  const PinholeCamera camera = testing_utils::TestCamera();
  const SE3 cur_from_ref = testing_utils::TestCurFromRef();
  const Eigen::Vector2d pixel_in_ref(70.0, 50.0);
  constexpr double kIdepth = 0.4;
  constexpr double kIdepthSigma = 0.05;  // ~0.9 px along the epipolar line
  const Eigen::Matrix3d model = ReprojectedPixelCovariance(camera, cur_from_ref, pixel_in_ref,
                                                           kIdepth, kIdepthSigma * kIdepthSigma);
  EXPECT_EQ(model.row(2).norm() + model.col(2).norm(), 0.0);
  std::mt19937 rng(43);
  std::normal_distribution<double> noise(0.0, kIdepthSigma);
  std::vector<Eigen::Vector2d> pixels;
  for (int k = 0; k < kSamples; ++k) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(Reproject(camera, cur_from_ref, pixel_in_ref, kIdepth + noise(rng), &pixel));
    pixels.push_back(pixel);
  }
  const Eigen::Matrix2d measured = SampleCovariance<2>(pixels);
  const Eigen::Matrix2d model_2d = model.topLeftCorner<2, 2>();
  EXPECT_LT(RelativeError(measured.trace(), model_2d.trace()), kModelTolerance);
  const Eigen::Vector2d along =
      ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, kIdepth).normalized();
  const Eigen::Vector2d across(-along.y(), along.x());
  EXPECT_LT(RelativeError(along.dot(measured * along), along.dot(model_2d * along)),
            kModelTolerance);
  // Rank one: the spread across the epipolar direction is negligible.
  EXPECT_LT(across.dot(measured * across), 1e-3 * measured.trace());
}

TEST(ReprojectionIdepthJacobian, MatchesCentralDifferences) {
  const PinholeCamera camera = testing_utils::TestCamera();
  const SE3 cur_from_ref = testing_utils::TestCurFromRef();
  const Eigen::Vector2d pixel_in_ref(30.0, 90.0);
  Eigen::Vector2d plus, minus;
  constexpr double kStep = 1e-6;  // truncation ~1e-12, rounding ~1e-8 px per unit idepth
  ASSERT_TRUE(Reproject(camera, cur_from_ref, pixel_in_ref, 0.3 + kStep, &plus));
  ASSERT_TRUE(Reproject(camera, cur_from_ref, pixel_in_ref, 0.3 - kStep, &minus));
  const Eigen::Vector2d numeric = (plus - minus) / (2.0 * kStep);
  EXPECT_LT((ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, 0.3) - numeric).norm(),
            1e-6);
}

// ------------------------------------------------------------------------------------------
// Photometric variance: the real PhotometricResidual evaluated on freshly noised images.

// A small scene where cur_from_ref is a pure translation that shifts every pixel at depth 1/d0
// by exactly (kx, ky) pixels, so reprojections land where we choose (integer positions or cell
// centres).
class PhotometricVarianceTest : public ::testing::Test {
 protected:
  PhotometricVarianceTest() {
    camera_.width = 24;
    camera_.height = 24;
    camera_.fx = 30.0;
    camera_.fy = 28.0;
    camera_.cx = 11.5;
    camera_.cy = 11.5;
    clean_ = testing_utils::SampleImage(camera_, [](double x, double y) {
      return testing_utils::SmoothIntensity(x + 20.0, y + 10.0);
    });
  }

  SE3 ShiftPose(double shift_x, double shift_y) const {
    const double depth = 1.0 / kIdepth;
    return SE3(Eigen::Matrix3d::Identity(),
               Eigen::Vector3d(shift_x * depth / camera_.fx, shift_y * depth / camera_.fy, 0.0));
  }

  // Samples r = I_ref(x) - I_cur(tau(x, d + n_d)) on images with fresh N(0, sigma_I^2) pixel
  // noise, through PhotometricResidual (sqrt_info 1). Returns the sample variance.
  double MonteCarloVariance(const SE3& cur_from_ref, const Eigen::Vector2d& pixel_in_ref,
                            double sigma_intensity, double idepth_sigma, unsigned seed) const {
    std::mt19937 rng(seed);
    std::normal_distribution<double> unit(0.0, 1.0);
    std::vector<double> residuals;
    residuals.reserve(kSamples);
    cv::Mat noisy_ref(clean_.size(), CV_32F), noisy_cur(clean_.size(), CV_32F);
    double pose[7];
    PoseToParameters(cur_from_ref, pose);
    const double* parameters[] = {pose};
    for (int k = 0; k < kSamples; ++k) {
      for (int y = 0; y < clean_.rows; ++y) {
        for (int x = 0; x < clean_.cols; ++x) {
          noisy_ref.at<float>(y, x) =
              clean_.at<float>(y, x) + static_cast<float>(sigma_intensity * unit(rng));
          noisy_cur.at<float>(y, x) =
              clean_.at<float>(y, x) + static_cast<float>(sigma_intensity * unit(rng));
        }
      }
      const ImagePyramid ref(noisy_ref, 1), cur(noisy_cur, 1);
      PhotometricObservation o;
      o.pixel_in_ref = pixel_in_ref;
      o.idepth = kIdepth + idepth_sigma * unit(rng);
      o.intensity_ref = ref.Sample(0, pixel_in_ref.x(), pixel_in_ref.y())[0];
      const PhotometricResidual residual(cur, 0, camera_, {o});
      double r;
      residual.Evaluate(parameters, &r, nullptr);
      EXPECT_TRUE(residual.valid(0));
      residuals.push_back(r);
    }
    return SampleVariance(residuals);
  }

  double ModelVariance(const SE3& cur_from_ref, const Eigen::Vector2d& pixel_in_ref,
                       double sigma_intensity, double idepth_sigma) const {
    const ImagePyramid cur(clean_, 1);
    Eigen::Vector2d pixel_cur;
    EXPECT_TRUE(Reproject(camera_, cur_from_ref, pixel_in_ref, kIdepth, &pixel_cur));
    const Eigen::Vector3f sample = cur.Sample(0, pixel_cur.x(), pixel_cur.y());
    return PhotometricVariance(
        sigma_intensity, Eigen::Vector2d(sample[1], sample[2]),
        ReprojectionIdepthJacobian(camera_, cur_from_ref, pixel_in_ref, kIdepth),
        idepth_sigma * idepth_sigma);
  }

  static constexpr double kIdepth = 0.5;
  PinholeCamera camera_;
  cv::Mat clean_;
};

// Image noise only, both samples at integer pixels: exactly the model's 2 sigma_I^2.
TEST_F(PhotometricVarianceTest, ImageNoiseAtIntegerPixels) {
  const SE3 cur_from_ref = ShiftPose(3.0, 2.0);
  const Eigen::Vector2d pixel_in_ref(9.0, 10.0);
  const double model = ModelVariance(cur_from_ref, pixel_in_ref, 2.0, 0.0);
  EXPECT_NEAR(model, 8.0, 1e-12);
  const double measured = MonteCarloVariance(cur_from_ref, pixel_in_ref, 2.0, 0.0, 1);
  EXPECT_LT(RelativeError(measured, model), kModelTolerance) << measured << " vs " << model;
}

// Inverse-depth noise only (0.3 px along the epipolar line), landing at a cell centre where the
// interpolated gradient equals the slope of the bilinear interpolant to O(h^2).
TEST_F(PhotometricVarianceTest, DepthNoiseThroughImageSampling) {
  const SE3 cur_from_ref = ShiftPose(3.5, 2.5);
  const Eigen::Vector2d pixel_in_ref(9.0, 10.0);
  const double idepth_sigma = 0.3 / (Eigen::Vector2d(3.5, 2.5).norm() / kIdepth);
  const double model = ModelVariance(cur_from_ref, pixel_in_ref, 0.0, idepth_sigma);
  const double measured = MonteCarloVariance(cur_from_ref, pixel_in_ref, 0.0, idepth_sigma, 2);
  EXPECT_GT(model, 1.0);  // a real geometric term, not a vanishing gradient
  EXPECT_LT(RelativeError(measured, model), kModelTolerance) << measured << " vs " << model;
}

// Both noises, landing at an integer pixel. Depth noise moves the sample off the pixel, where
// bilinear interpolation averages the current image's noise (variance factor sum w_i^2 < 1), so
// the model's 2 sigma_I^2 overestimates slightly; still within the bound here (measured 4.5%
// below the model).
TEST_F(PhotometricVarianceTest, CombinedNoise) {
  const SE3 cur_from_ref = ShiftPose(3.0, 2.0);
  const Eigen::Vector2d pixel_in_ref(9.0, 10.0);
  const double idepth_sigma = 0.3 / (Eigen::Vector2d(3.0, 2.0).norm() / kIdepth);
  const double model = ModelVariance(cur_from_ref, pixel_in_ref, 1.0, idepth_sigma);
  const double measured = MonteCarloVariance(cur_from_ref, pixel_in_ref, 1.0, idepth_sigma, 3);
  RecordProperty("combined_measured_over_model", std::to_string(measured / model));
  EXPECT_LT(RelativeError(measured, model), kModelTolerance) << measured << " vs " << model;
}

// The documented limitation: at a cell centre the current sample averages 4 noisy pixels
// (sum w_i^2 = 1/4), so the true image term is (1 + 1/4) sigma_I^2 and the model's 2 sigma_I^2
// is conservative by 1.6x. Checked against the interpolation-aware value.
TEST_F(PhotometricVarianceTest, SubPixelImageNoiseIsBelowModel) {
  const SE3 cur_from_ref = ShiftPose(3.5, 2.5);
  const Eigen::Vector2d pixel_in_ref(9.0, 10.0);
  const double model = ModelVariance(cur_from_ref, pixel_in_ref, 2.0, 0.0);
  const double measured = MonteCarloVariance(cur_from_ref, pixel_in_ref, 2.0, 0.0, 4);
  EXPECT_LT(RelativeError(measured, 1.25 * 4.0), kModelTolerance) << measured;
  EXPECT_LT(measured, model);
}

// ------------------------------------------------------------------------------------------
// Point-to-line variance: noisy endpoints -> FitLine, noisy inverse depth -> Reproject.

TEST(PointToLineVariance, MatchesMonteCarlo) {
  const PinholeCamera camera = testing_utils::TestCamera();
  const SE3 cur_from_ref = testing_utils::TestCurFromRef();
  const Eigen::Vector2d pixel_in_ref(100.0, 40.0);
  constexpr double kIdepth = 0.35;
  constexpr double kIdepthSigma = 0.06;
  constexpr double kSigmaPx = 1.0;
  Eigen::Vector2d pixel_cur;
  ASSERT_TRUE(Reproject(camera, cur_from_ref, pixel_in_ref, kIdepth, &pixel_cur));
  // A 60 px line at 60 degrees to the epipolar direction (so the depth error moves the point
  // across it), with its midpoint 25 px along it from the reprojection and 1.5 px off it (so
  // the angular line error matters too).
  const Eigen::Vector2d epipolar =
      ReprojectionIdepthJacobian(camera, cur_from_ref, pixel_in_ref, kIdepth).normalized();
  const Eigen::Vector2d direction = Eigen::Rotation2Dd(60.0 * 3.141592653589793 / 180.0) * epipolar;
  const Eigen::Vector2d normal(-direction.y(), direction.x());
  const Eigen::Vector2d middle = pixel_cur + 25.0 * direction + 1.5 * normal;
  const Eigen::Vector2d p1 = middle - 30.0 * direction, p2 = middle + 30.0 * direction;

  const LineWithCovariance line = FitLine(p1, p2, kSigmaPx);
  const Eigen::Matrix3d pixel_cov = ReprojectedPixelCovariance(
      camera, cur_from_ref, pixel_in_ref, kIdepth, kIdepthSigma * kIdepthSigma);
  const double model = PointToLineVariance(line.line, line.cov, pixel_cur, pixel_cov);
  // Both terms contribute at least a fifth.
  const Eigen::Vector3d x(pixel_cur.x(), pixel_cur.y(), 1.0);
  EXPECT_GT(line.line.dot(pixel_cov * line.line), 0.2 * model);
  EXPECT_GT(x.dot(line.cov * x), 0.2 * model);

  std::mt19937 rng(44);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> distances;
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector2d q1 = p1 + kSigmaPx * DrawVector2(unit, rng);
    const Eigen::Vector2d q2 = p2 + kSigmaPx * DrawVector2(unit, rng);
    const Eigen::Vector3d l = FitLine(q1, q2, 0.0).line;
    Eigen::Vector2d pixel;
    ASSERT_TRUE(
        Reproject(camera, cur_from_ref, pixel_in_ref, kIdepth + kIdepthSigma * unit(rng), &pixel));
    distances.push_back(l.dot(Eigen::Vector3d(pixel.x(), pixel.y(), 1.0)));
  }
  const double measured = SampleVariance(distances);
  EXPECT_LT(RelativeError(measured, model), kModelTolerance) << measured << " vs " << model;
}

}  // namespace
}  // namespace pldvo
