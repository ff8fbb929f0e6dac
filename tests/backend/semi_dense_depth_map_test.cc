// The semi-dense depth map's EKF update and bookkeeping, the epipolar geometry and the SSD search
// of backend/mapping/epipolar_stereo.h, propagation, regularisation and the output helpers.
#include "backend/mapping/semi_dense_depth_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "backend/mapping/depth_map_io.h"
#include "backend/mapping/depth_propagation.h"
#include "backend/mapping/depth_regularizer.h"
#include "backend/mapping/epipolar_stereo.h"
#include "tests/random_texture.h"

namespace pldvo {
namespace {

PinholeCamera TestCamera() { return PinholeCamera{160, 120, 130.0, 130.0, 79.5, 59.5}; }

// A fronto-parallel plane of blurred random texture at plane_depth seen from the origin (ref) and
// from +0.1 m in x (cur: the reference shifted left by fx * 0.1 / plane_depth px), each image with
// independent Gaussian noise of noise_sigma gray levels (CV_32F).
struct PlanePair {
  cv::Mat ref, cur;
  SE3 cur_from_ref;
  double shift_px;
};

PlanePair MakePlanePair(const PinholeCamera& camera, double plane_depth, uint64_t seed,
                        double noise_sigma, double blur_sigma = 1.2) {
  cv::RNG rng(seed);
  cv::Mat texture = test::RandomTexture(cv::Size(camera.width + 60, camera.height + 60), rng,
                                        blur_sigma, cv::Size(5, 5));
  texture.convertTo(texture, CV_32F);
  PlanePair pair;
  pair.shift_px = camera.fx * 0.1 / plane_depth;
  pair.cur_from_ref = SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.1, 0.0, 0.0));
  pair.ref = texture(cv::Rect(20, 20, camera.width, camera.height)).clone();
  const cv::Mat warp = (cv::Mat_<double>(2, 3) << 1, 0, 20 + pair.shift_px, 0, 1, 20);
  cv::warpAffine(texture, pair.cur, warp, cv::Size(camera.width, camera.height),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
  if (noise_sigma > 0.0) {
    cv::Mat noise(pair.ref.size(), CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    pair.ref += noise;
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    pair.cur += noise;
  }
  return pair;
}

// Calls on_match(observation) for every pixel of a 2-px grid (x >= x_min, 10-px margins) whose
// epipolar patch and SSD search over [idepth_min, idepth_max] succeed.
template <class OnMatch>
void SearchPlaneGrid(const PinholeCamera& camera, const PlanePair& pair,
                     const MappingOptions& options, int x_min, double idepth_min, double idepth_max,
                     OnMatch on_match) {
  const ImagePyramid ref(pair.ref, 1), cur(pair.cur, 1);
  const EpipolarGeometry geometry(camera, pair.cur_from_ref);
  for (int y = 10; y < camera.height - 10; y += 2) {
    for (int x = x_min; x < camera.width - 10; x += 2) {
      const Eigen::Vector2d pixel(x, y);
      EpipolarPatch patch;
      StereoObservation observation;
      if (MakeEpipolarPatch(ref, geometry, pixel, 0.5, options, &patch) == StereoStatus::kOk &&
          SearchEpipolarSsd(cur, geometry, patch, pixel, idepth_min, idepth_max, options,
                            &observation) == StereoStatus::kOk) {
        on_match(observation);
      }
    }
  }
}

TEST(SemiDenseDepthMapTest, FuseIsProductOfGaussians) {
  SemiDenseDepthMap map(4, 4);
  MappingOptions options;
  map.Set(5, 0.5, 0.04, options.validity_initial);
  ASSERT_TRUE(map.Fuse(5, 0.6, 0.01, /*correlation=*/0.0, options));
  // (0.01 * 0.5 + 0.04 * 0.6) / 0.05 = 0.58, 0.04 * 0.01 / 0.05 = 0.008 (float storage).
  EXPECT_NEAR(map.idepth(5), 0.58, 1e-6);
  EXPECT_NEAR(map.idepth_var(5), 0.008, 1e-8);
  EXPECT_EQ(map.validity(5), options.validity_initial + options.validity_increment);
  EXPECT_EQ(map.num_observations(5), 1);
}

TEST(SemiDenseDepthMapTest, CorrelatedFusionHasTheEquicorrelatedVarianceFloor) {
  // n observations of equal variance s^2 with pairwise correlation rho into an uninformative
  // prior: the best linear estimate is their mean, of variance rho s^2 + (1 - rho) s^2 / n.
  const double rho = 0.3, obs_var = 0.01;
  MappingOptions options;
  options.outlier_gate_sigmas = 1e6;
  SemiDenseDepthMap map(1, 1);
  map.Set(0, 0.5, 1e8, options.validity_initial);
  for (int n = 1; n <= 20; ++n) {
    ASSERT_TRUE(map.Fuse(0, 0.5 + 0.01 * (n % 3), obs_var, rho, options));
    const double expected = rho * obs_var + (1.0 - rho) * obs_var / n;
    // Relative 1e-5: float storage (6e-8) and the prior's 1e-10 weight.
    EXPECT_NEAR(map.idepth_var(0), expected, 1e-5 * expected) << n;
    EXPECT_NEAR(map.idepth_shared_sd(0), std::sqrt(rho * obs_var), 1e-5) << n;
  }
  // The mean of the 20 observations (0.5 + 0.01 * (n % 3): seven 0.51, seven 0.52, six 0.50).
  EXPECT_NEAR(map.idepth(0), 0.5 + (7 * 0.01 + 7 * 0.02) / 20.0, 1e-6);
}

TEST(SemiDenseDepthMapTest, CorrelatedFusionIsConsistentByMonteCarlo) {
  // Simulates the model of SemiDenseDepthMap::Fuse: a prior N(d, 1) (the random initialisation),
  // then 12 stereo observations whose variance shrinks as the baseline grows,
  // s_k = 0.08 / (1 + k) (1/m), error sqrt(rho) s_k u + sqrt(1 - rho) s_k w_k with u shared by
  // the pixel's observations; every fourth observation comes from an independent source (the
  // edge BA's line depth: correlation 0). 20 000 pixels. The fused NEES is chi^2(1): mean 1
  // (standard error sqrt(2 / 20000) = 0.01, tolerance 5 standard errors), 0.1% above 10.83
  // (binomial standard error 0.02%); measured 0.989 and 0.04%. The EKF that treats the errors
  // as independent is overconfident on the same samples: measured mean NEES 2.13 and 2.45% gross
  // (required: > 1.5 and > 1%, far outside the consistent band).
  const int num_pixels = 20000, num_obs = 12;
  const double rho = 0.3, true_idepth = 0.7;
  MappingOptions options;
  options.outlier_gate_sigmas = 1e6;  // the model has no outliers; the gate would truncate it
  for (const bool correlated_model : {true, false}) {
    SemiDenseDepthMap map(num_pixels, 1);
    std::mt19937 rng(42);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int i = 0; i < num_pixels; ++i) {
      map.Set(i, true_idepth + normal(rng), 1.0, options.validity_initial);
      const double u = normal(rng);
      for (int k = 0; k < num_obs; ++k) {
        const double sigma = 0.08 / (1.0 + k);
        const bool independent = k % 4 == 3;
        const double shared = independent ? 0.0 : rho;
        const double error =
            sigma * (std::sqrt(shared) * u + std::sqrt(1.0 - shared) * normal(rng));
        ASSERT_TRUE(map.Fuse(i, true_idepth + error, sigma * sigma, correlated_model ? shared : 0.0,
                             options));
      }
    }
    double mean_nees = 0.0;
    int gross = 0;
    for (int i = 0; i < num_pixels; ++i) {
      const double error = map.idepth(i) - true_idepth;
      const double nees = error * error / map.idepth_var(i);
      mean_nees += nees / num_pixels;
      gross += nees > 10.83;
    }
    if (correlated_model) {
      EXPECT_NEAR(mean_nees, 1.0, 0.05);
      EXPECT_LT(static_cast<double>(gross) / num_pixels, 0.002);
    } else {
      EXPECT_GT(mean_nees, 1.5);
      EXPECT_GT(static_cast<double>(gross) / num_pixels, 0.01);
    }
  }
}

TEST(SemiDenseDepthMapTest, OutliersDecreaseValidityAndInvalidate) {
  SemiDenseDepthMap map(4, 4);
  MappingOptions options;
  map.Set(0, 0.5, 1e-4, 10);
  // 0.1 away at sigma sqrt(2e-4) = 0.014: 7 sigma, beyond the 2-sigma gate.
  EXPECT_FALSE(map.Fuse(0, 0.6, 1e-4, options));
  EXPECT_TRUE(map.valid(0));
  EXPECT_EQ(map.validity(0), 5);
  EXPECT_FLOAT_EQ(map.idepth(0), 0.5f);
  EXPECT_FALSE(map.Fuse(0, 0.6, 1e-4, options));
  EXPECT_FALSE(map.valid(0));
}

TEST(SemiDenseDepthMapTest, InlierRatioUpdateIsTheConjugateBetaUpdateForCertainClasses) {
  // When the class of an observation is certain, the moment-matched Beta update of
  // Vogiatzis & Hernandez reduces to the conjugate one: a + 1 for an inlier, b + 1 for an
  // outlier, and the hypothesis is dropped once a / (a + b) < min_inlier_ratio.
  MappingOptions options;
  options.outlier_model = MappingOptions::OutlierModel::kInlierRatio;
  options.min_inlier_ratio = 0.105;  // away from the ratios 11 / (21 + n) of the outlier run
  SemiDenseDepthMap map(1, 1);
  map.Set(0, 0.5, 1e-8, options.validity_initial);
  map.CountObservation(0);  // an observed hypothesis: the mixture classifies its observations
  // At the prior's mean with sigma 1.4e-4: density 2821 against the outlier's 0.2.
  EXPECT_TRUE(map.Fuse(0, 0.5, 1e-8, 0.0, options));
  EXPECT_NEAR(map.inlier_evidence(0), 1.0, 1e-3);
  EXPECT_NEAR(map.outlier_evidence(0), 0.0, 1e-3);
  EXPECT_EQ(map.num_observations(0), 2);
  // 1/m away, 7000 sigma: certainly an outlier. The mean and variance stay.
  const float idepth = map.idepth(0), idepth_var = map.idepth_var(0);
  EXPECT_FALSE(map.Fuse(0, 1.5, 1e-8, 0.0, options));
  EXPECT_NEAR(map.inlier_evidence(0), 1.0, 1e-3);
  EXPECT_NEAR(map.outlier_evidence(0), 1.0, 1e-3);
  EXPECT_EQ(map.idepth(0), idepth);
  EXPECT_EQ(map.idepth_var(0), idepth_var);
  EXPECT_EQ(map.num_observations(0), 2);
  // After n outliers a = 11, b = 10 + n: 11 / (21 + n) < 0.105 first at n = 84.
  int outliers = 1;
  while (map.valid(0) && outliers < 200) {
    map.Fuse(0, 1.5, 1e-8, 0.0, options);
    ++outliers;
  }
  EXPECT_EQ(outliers, 84);
}

TEST(SemiDenseDepthMapTest, InlierRatioTakesTheFirstObservationOfAnUnobservedHypothesis) {
  // A random initial hypothesis (V = 1) is as wide as the outlier density, so the mixture would
  // give an observation 1.5 1/m away the responsibility 10 N(1.5 | 0, 1) / (10 N + 10 U) = 0.39;
  // the first observation is taken as an inlier instead, as in an unmapped pixel.
  MappingOptions options;
  options.outlier_model = MappingOptions::OutlierModel::kInlierRatio;
  SemiDenseDepthMap map(1, 1);
  map.Set(0, 0.5, 1.0, options.validity_initial);
  EXPECT_TRUE(map.Fuse(0, 2.0, 1e-4, 0.0, options));
  EXPECT_NEAR(map.idepth(0), (1e-4 * 0.5 + 1.0 * 2.0) / (1.0 + 1e-4), 1e-6);
  EXPECT_NEAR(map.idepth_var(0), 1e-4 / (1.0 + 1e-4), 1e-9);
  EXPECT_NEAR(map.inlier_evidence(0), 1.0, 1e-6);
  EXPECT_NEAR(map.outlier_evidence(0), 0.0, 1e-6);
}

// What a filter leaves of 20 000 pixels of inverse depth 0.7 after 30 observations, each with
// probability inlier_probability an inlier N(0.7, s_k^2), s_k = 0.08 / (1 + k / 3), else uniform
// on [min_idepth, max_idepth] (the model of the kInlierRatio fusion). The first observation
// creates the hypothesis (as in an unmapped pixel, or the random initialisation's first fusion);
// with first_is_inlier it is always an inlier.
struct OutlierFilterStats {
  double kept_fraction, mean_nees, gross_fraction, mean_inlier_ratio;
};

OutlierFilterStats SimulateOutlierFilter(MappingOptions::OutlierModel model,
                                         double inlier_probability, bool first_is_inlier) {
  const int num_pixels = 20000, num_obs = 30;
  const double true_idepth = 0.7;
  MappingOptions options;
  options.outlier_model = model;
  SemiDenseDepthMap map(num_pixels, 1);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> outlier(options.min_idepth, options.max_idepth);
  for (int i = 0; i < num_pixels; ++i) {
    map.Set(i, true_idepth + normal(rng), 1.0, options.validity_initial);  // random init
    for (int k = 0; k < num_obs && map.valid(i); ++k) {
      const double sigma = 0.08 / (1.0 + k / 3.0);
      const bool inlier = (k == 0 && first_is_inlier) || unit(rng) < inlier_probability;
      const double obs = inlier ? true_idepth + sigma * normal(rng) : outlier(rng);
      map.Fuse(i, obs, sigma * sigma, /*correlation=*/0.0, options);
    }
  }
  OutlierFilterStats stats{0.0, 0.0, 0.0, 0.0};
  int valid = 0;
  for (int i = 0; i < num_pixels; ++i) {
    if (!map.valid(i)) continue;
    ++valid;
    const double error = map.idepth(i) - true_idepth;
    const double nees = error * error / map.idepth_var(i);
    stats.mean_nees += nees;
    stats.gross_fraction += nees > 10.83;
    const double a = options.inlier_prior_count + map.inlier_evidence(i);
    const double b = options.inlier_prior_count + map.outlier_evidence(i);
    stats.mean_inlier_ratio += a / (a + b);
  }
  stats.kept_fraction = static_cast<double>(valid) / num_pixels;
  stats.mean_nees /= valid;
  stats.gross_fraction /= valid;
  stats.mean_inlier_ratio /= valid;
  return stats;
}

TEST(SemiDenseDepthMapTest, InlierRatioFilterIsConsistentUnderUniformOutliers) {
  // SimulateOutlierFilter at 30% outliers. Hypotheses created from an inlier: the mixture keeps
  // every pixel and its NEES is chi^2(1): measured mean 1.021 (standard error 0.01), 0.14% above
  // 10.83 (without the C1 C2 (m - mu)^2 term of V', a mutation, 1.206 and 0.37%); its expected
  // inlier ratio 0.624 (the posterior mean of pi from Beta(10, 10) and ~21 of 30 inliers is
  // ~0.63). The validity counter on the same samples drops 10% of the pixels (the random prior
  // is more than 2 sigma off, or an outlier passes the gate while the prior is wide; then the
  // inliers fail the gate) and is overconfident on the rest (the gate cuts the inliers' tails):
  // mean NEES 1.380, 0.62% gross. Other rates: docs/mapping.md.
  using Model = MappingOptions::OutlierModel;
  const OutlierFilterStats ratio = SimulateOutlierFilter(Model::kInlierRatio, 0.7, true);
  EXPECT_EQ(ratio.kept_fraction, 1.0);
  EXPECT_NEAR(ratio.mean_nees, 1.0, 0.08);
  EXPECT_LT(ratio.gross_fraction, 0.003);
  EXPECT_NEAR(ratio.mean_inlier_ratio, 0.63, 0.03);
  const OutlierFilterStats counter = SimulateOutlierFilter(Model::kValidityCounter, 0.7, true);
  EXPECT_LT(counter.kept_fraction, 0.95);
  EXPECT_GT(counter.mean_nees, 1.2);
  // The mixture's weakness, at 10% outliers with the first observation drawn like the others: a
  // hypothesis created from an outlier (10% of them) stays until its inlier ratio falls below
  // 0.1, ~80 observations later. Measured: 8.3% gross, mean NEES 120; the validity counter drops
  // them (kept 89.9%, mean NEES 1.385).
  const OutlierFilterStats ratio_bad_start = SimulateOutlierFilter(Model::kInlierRatio, 0.9, false);
  EXPECT_GT(ratio_bad_start.gross_fraction, 0.05);
  const OutlierFilterStats counter_bad_start =
      SimulateOutlierFilter(Model::kValidityCounter, 0.9, false);
  EXPECT_LT(counter_bad_start.kept_fraction, 0.92);
  EXPECT_LT(counter_bad_start.mean_nees, 1.5);
}

TEST(SemiDenseDepthMapTest, RandomInitialisationIsDeterministicAndInRange) {
  const cv::Mat image(40, 40, CV_8U, cv::Scalar(0));
  cv::Mat textured = image.clone();
  cv::randu(textured, 0, 255);
  const ImagePyramid pyramid(textured, 1);
  MappingOptions options;
  SemiDenseDepthMap a(40, 40), b(40, 40);
  a.SelectPixels(pyramid, cv::Mat(), options);
  b.SelectPixels(pyramid, cv::Mat(), options);
  a.InitializeRandom(0.2, 1.5, 1.0, 3, 20);
  b.InitializeRandom(0.2, 1.5, 1.0, 3, 20);
  ASSERT_GT(a.CountCandidates(), 100);
  EXPECT_EQ(a.CountValid(), a.CountCandidates());
  for (int i = 0; i < a.num_pixels(); ++i) {
    if (!a.valid(i)) continue;
    EXPECT_EQ(a.idepth(i), b.idepth(i));
    EXPECT_GE(a.idepth(i), 0.2f);
    EXPECT_LE(a.idepth(i), 1.5f);
    EXPECT_EQ(a.num_observations(i), 0);
  }
  // Nothing within border_px of the border.
  EXPECT_FALSE(a.candidate(a.Index(1, 20)));
}

TEST(EpipolarGeometryTest, ProjectionJacobianAndInverse) {
  const PinholeCamera camera = TestCamera();
  const SE3 cur_from_ref = SE3::Exp((Vector6d() << 0.1, -0.05, 0.03, 0.02, 0.05, -0.01).finished());
  const EpipolarGeometry geometry(camera, cur_from_ref);
  const Eigen::Vector2d pixel(50.0, 70.0);
  const double idepth = 0.4;
  Eigen::Vector2d projected;
  ASSERT_TRUE(geometry.Project(pixel, idepth, &projected));
  const Eigen::Vector3d point = cur_from_ref * (camera.Unproject(pixel) / idepth);
  EXPECT_LT((projected - camera.Project(point)).norm(), 1e-9);
  const double h = 1e-6;
  Eigen::Vector2d plus, minus;
  geometry.Project(pixel, idepth + h, &plus);
  geometry.Project(pixel, idepth - h, &minus);
  EXPECT_LT((geometry.IdepthJacobian(pixel, idepth) - (plus - minus) / (2 * h)).norm(), 1e-5);
  EXPECT_NEAR(geometry.IdepthFromCurPixel(pixel, projected, plus - minus), idepth, 1e-9);
}

// The pose error's offset across the epipolar line, n^T J Sigma J^T n, against the offsets of
// the point reprojected with Exp(delta) * cur_from_ref for delta ~ N(0, Sigma): a correlated
// Sigma (2-5 mm, 0.1-0.3 deg), a near point, a far one and the point at infinity (d = 0).
TEST(EpipolarGeometryTest, PoseOffsetVarMatchesMonteCarlo) {
  const PinholeCamera camera = TestCamera();
  const SE3 cur_from_ref = SE3::Exp((Vector6d() << 0.1, -0.05, 0.03, 0.02, 0.05, -0.01).finished());
  Matrix6d a = Matrix6d::Zero();
  a.diagonal() << 0.005, 0.003, 0.002, 0.005, 0.002, 0.003;
  a(0, 4) = 0.003;  // translation correlated with rotation, as in tracking
  a(1, 3) = -0.002;
  const Matrix6d sigma = a * a.transpose();
  const EpipolarGeometry geometry(camera, cur_from_ref, sigma);
  EXPECT_EQ(EpipolarGeometry(camera, cur_from_ref)
                .PoseOffsetVar(Eigen::Vector2d(50, 70), 0.4, Eigen::Vector2d(0, 1)),
            0.0);
  const Eigen::LLT<Matrix6d> llt(sigma);
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (const double idepth : {2.0, 0.4, 0.0}) {
    const Eigen::Vector2d pixel(50.0, 70.0);
    Eigen::Vector2d projected, farther;
    ASSERT_TRUE(geometry.Project(pixel, idepth, &projected));
    ASSERT_TRUE(geometry.Project(pixel, idepth + 0.1, &farther));
    const Eigen::Vector2d along = (farther - projected).normalized();
    const Eigen::Vector2d across(-along.y(), along.x());
    const double model = geometry.PoseOffsetVar(pixel, idepth, across);
    const int samples = 20000;
    double sum = 0.0, sum_sq = 0.0;
    for (int k = 0; k < samples; ++k) {
      Vector6d z;
      for (int i = 0; i < 6; ++i) z[i] = normal(rng);
      const EpipolarGeometry perturbed(camera, SE3::Exp(llt.matrixL() * z) * cur_from_ref);
      Eigen::Vector2d moved;
      ASSERT_TRUE(perturbed.Project(pixel, idepth, &moved));
      const double offset = across.dot(moved - projected);
      sum += offset;
      sum_sq += offset * offset;
    }
    const double mean = sum / samples;
    const double variance = sum_sq / samples - mean * mean;
    // 20000 samples: the sample variance's relative standard error is sqrt(2 / n) = 1%.
    EXPECT_NEAR(variance / model, 1.0, 0.04) << "idepth " << idepth << " model " << model;
    EXPECT_GT(model, 0.1) << "idepth " << idepth;  // pixels^2: the test is not trivially small
  }
}

// A fronto-parallel textured plane at 2 m seen with a 10 cm sideways baseline: the SSD search
// from a wide prior finds the true inverse depth within 3 sigma of its own variance.
TEST(EpipolarStereoTest, SsdSearchFindsPlaneDepth) {
  const PinholeCamera camera = TestCamera();
  const PlanePair pair = MakePlanePair(camera, 2.0, 7, 0.0);
  const ImagePyramid ref(pair.ref, 1), cur(pair.cur, 1);
  const EpipolarGeometry geometry(camera, pair.cur_from_ref);
  MappingOptions options;
  int found = 0, consistent = 0;
  for (int y = 20; y < 100; y += 7) {
    for (int x = 30; x < 130; x += 7) {
      const Eigen::Vector2d pixel(x, y);
      EpipolarPatch patch;
      if (MakeEpipolarPatch(ref, geometry, pixel, 0.5, options, &patch) != StereoStatus::kOk) {
        continue;
      }
      StereoObservation observation;
      if (SearchEpipolarSsd(cur, geometry, patch, pixel, 0.0, 2.0, options, &observation) !=
          StereoStatus::kOk) {
        continue;
      }
      ++found;
      const double error = observation.idepth - 0.5;
      consistent += error * error <= 9.0 * observation.idepth_var;
    }
  }
  EXPECT_GT(found, 60);
  // Random texture: a few ambiguous matches may remain; 90% must be within 3 sigma.
  EXPECT_GT(consistent, 0.9 * found);
}

// Forward and backward motion towards a fronto-parallel textured plane at 2 m: the current image
// is the reference scaled about the principal point by 2 / (2 - t_z), so the patch's sample
// spacing in the current frame is 1.33 or 0.87 px and the search steps are a third or a half of
// it. Both scales must find the plane. The patch runs against the search direction here (as it
// does whenever the point is in front of both cameras); the same patch reversed (samples in
// the opposite order, step_cur negated) must give the identical observation.
TEST(EpipolarStereoTest, SsdSearchFindsPlaneDepthUnderForwardAndBackwardMotion) {
  const PinholeCamera camera = TestCamera();
  cv::Mat texture =
      test::RandomTexture(cv::Size(camera.width + 60, camera.height + 60), 11, 1.2, cv::Size(5, 5));
  texture.convertTo(texture, CV_32F);
  const cv::Mat ref_image = texture(cv::Rect(20, 20, camera.width, camera.height)).clone();
  const ImagePyramid ref(ref_image, 1);
  const MappingOptions options;
  for (const double t_z : {0.5, -0.3}) {
    const double scale = 2.0 / (2.0 - t_z);
    // cur(x) = texture(20 + c + (x - c) / scale).
    const cv::Mat warp =
        (cv::Mat_<double>(2, 3) << 1.0 / scale, 0, 20 + camera.cx * (1 - 1 / scale), 0, 1.0 / scale,
         20 + camera.cy * (1 - 1 / scale));
    cv::Mat cur_image;
    cv::warpAffine(texture, cur_image, warp, cv::Size(camera.width, camera.height),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    const ImagePyramid cur(cur_image, 1);
    const EpipolarGeometry geometry(camera,
                                    SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, -t_z)));
    int found = 0, consistent = 0, against = 0, reversed_equal = 0;
    std::vector<double> errors;
    for (int y = 6; y < camera.height - 6; y += 3) {
      for (int x = 6; x < camera.width - 6; x += 3) {
        const Eigen::Vector2d pixel(x, y);
        if ((pixel - Eigen::Vector2d(camera.cx, camera.cy)).norm() < 30.0) continue;  // epipole
        EpipolarPatch patch;
        StereoObservation observation;
        Eigen::Vector2d p_far, p_near;
        if (MakeEpipolarPatch(ref, geometry, pixel, 0.5, options, &patch) != StereoStatus::kOk ||
            SearchEpipolarSsd(cur, geometry, patch, pixel, 0.3, 0.7, options, &observation) !=
                StereoStatus::kOk ||
            !geometry.Project(pixel, 0.3, &p_far) || !geometry.Project(pixel, 0.7, &p_near)) {
          continue;
        }
        ++found;
        against += patch.step_cur.dot(p_near - p_far) < 0.0;
        const double error = observation.idepth - 0.5;
        consistent += error * error <= 9.0 * observation.idepth_var;
        errors.push_back(std::abs(error) / 0.5);
        EpipolarPatch reversed = patch;
        std::reverse(std::begin(reversed.ref), std::end(reversed.ref));
        reversed.step_cur = -patch.step_cur;
        StereoObservation reversed_observation;
        reversed_equal += SearchEpipolarSsd(cur, geometry, reversed, pixel, 0.3, 0.7, options,
                                            &reversed_observation) == StereoStatus::kOk &&
                          std::abs(reversed_observation.idepth - observation.idepth) < 1e-9 &&
                          std::abs(reversed_observation.idepth_var - observation.idepth_var) <
                              1e-9 * observation.idepth_var;
      }
    }
    std::sort(errors.begin(), errors.end());
    std::printf(
        "t_z %+.1f: %d matches (%d against the search), %.3f within 3 sigma, median rel. "
        "error %.4f\n",
        t_z, found, against, static_cast<double>(consistent) / found, errors[errors.size() / 2]);
    EXPECT_GT(found, 300);
    EXPECT_EQ(against, found);
    EXPECT_EQ(reversed_equal, found);
    EXPECT_GT(consistent, 0.9 * found);
    EXPECT_LT(errors[errors.size() / 2], 0.015);
  }
}

// A search whose interval partly leaves the current image cannot tell a match: the true one of
// this pixel (plane at 1 m, 13 px disparity) lies left of the image, and an exact copy of its
// patch is pasted inside the interval at 5 px. The truncated search must not report the copy.
TEST(EpipolarStereoTest, SsdSearchRejectsAnIntervalThatLeavesTheImage) {
  const PinholeCamera camera = TestCamera();
  PlanePair pair = MakePlanePair(camera, 1.0, 11, 0.0);
  const double shift = pair.shift_px;  // 13 px
  const int x = 10, y = 60, decoy_disparity = 5;
  pair.ref(cv::Rect(x - 3, y - 2, 7, 5))
      .copyTo(pair.cur(cv::Rect(x - decoy_disparity - 3, y - 2, 7, 5)));
  const ImagePyramid ref(pair.ref, 1), cur(pair.cur, 1);
  const EpipolarGeometry geometry(camera, pair.cur_from_ref);
  const MappingOptions options;
  const Eigen::Vector2d pixel(x, y);
  EpipolarPatch patch;
  ASSERT_EQ(MakeEpipolarPatch(ref, geometry, pixel, 0.5, options, &patch), StereoStatus::kOk);
  StereoObservation observation;
  // Interval [0, 2] 1/m: 0 to 26 px of disparity, the true match at 13 px is outside.
  EXPECT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.0, 2.0, options, &observation),
            StereoStatus::kTruncated);
  // The same decoy inside a fully sampled interval [0, 0.5] (0 to 6.5 px) is found: the rule,
  // not the texture, rejects the truncated search.
  ASSERT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.0, 0.5, options, &observation),
            StereoStatus::kOk);
  EXPECT_NEAR(observation.idepth, decoy_disparity / shift, 0.02);
}

// Monte Carlo of the SSD observation variance when the image noise is 4 gray levels but the
// model assumes sigma_I = 1: Engel's variance is overconfident, the residual-scaled one
// (options.residual_intensity_noise) is consistent. Plane at 2 m, prior [0.3, 0.7] 1/m.
TEST(EpipolarStereoTest, ResidualScaledNoiseKeepsTheObservationVarianceConsistent) {
  const PinholeCamera camera = TestCamera();
  const PlanePair pair = MakePlanePair(camera, 2.0, 5, 4.0);
  auto within_2_sigma = [&](bool residual_noise, int* count) {
    MappingOptions options;
    options.sigma_intensity = 1.0;
    options.sigma_epipolar_px = 0.05;
    options.residual_intensity_noise = residual_noise;
    options.ssd_ambiguity_variance = false;  // the noise model alone
    int found = 0, within = 0;
    SearchPlaneGrid(camera, pair, options, 20, 0.3, 0.7, [&](const StereoObservation& obs) {
      ++found;
      const double error = obs.idepth - 0.5;
      within += error * error <= 4.0 * obs.idepth_var;
    });
    *count = found;
    return static_cast<double>(within) / found;
  };
  int found_engel = 0, found_residual = 0;
  const double engel = within_2_sigma(false, &found_engel);
  const double residual = within_2_sigma(true, &found_residual);
  std::printf("within 2 sigma: Engel %.3f (%d matches), residual-scaled %.3f (%d)\n", engel,
              found_engel, residual, found_residual);
  ASSERT_GT(found_residual, 1000);
  EXPECT_GT(residual, 0.90);  // 0.954 if consistent
  EXPECT_LT(engel, 0.80);
}

// Gross matches (more than 1 px of disparity off) of the wide search [0, 2] 1/m over a plane
// whose texture is only lightly blurred, at depths that put the true disparity midway between
// two 1-px steps (the worst case of 1-px sampling).
struct SearchCount {
  int found = 0, gross = 0;
};

SearchCount SearchAFineTextureAtHalfPixelDisparities(double step_px) {
  const PinholeCamera camera = TestCamera();
  MappingOptions options;
  options.sigma_intensity = 1.0;
  options.ssd_search_step_px = step_px;
  SearchCount count;
  for (const double shift : {5.5, 6.5, 7.5, 8.5}) {
    const PlanePair pair =
        MakePlanePair(camera, camera.fx * 0.1 / shift, 3, 1.0, /*blur_sigma=*/0.7);
    SearchPlaneGrid(camera, pair, options, 40, 0.0, 2.0, [&](const StereoObservation& obs) {
      ++count.found;
      count.gross += std::abs(obs.idepth * camera.fx * 0.1 - shift) > 1.0;
    });
  }
  std::printf("step %.1f px: %d matches, %.4f gross\n", step_px, count.found,
              static_cast<double>(count.gross) / count.found);
  return count;
}

TEST(EpipolarStereoTest, HalfPixelStepsFindTheMatchesOfAFineTexture) {
  const SearchCount one = SearchAFineTextureAtHalfPixelDisparities(1.0);
  const SearchCount half = SearchAFineTextureAtHalfPixelDisparities(0.5);
  ASSERT_GT(one.found, 1000);
  // Measured: 8.8% of 5707 matches gross with 1-px steps, 3.1% of 7286 with half-pixel steps.
  EXPECT_GT(half.found, one.found);
  EXPECT_LT(static_cast<double>(half.gross) / half.found,
            0.5 * static_cast<double>(one.gross) / one.found);
}

// A decoy of the pixel's patch, one gray level brighter, 6 px from the true match (plane at
// 1.3 m, 10 px, sampled exactly by a half-pixel step): SSD 5 against 0 at the steps, likelihood
// ratio w = exp(-5 / (4 sigma_I^2)) with sigma_I = 1 (not residual-scaled here), so the
// observation variance grows by w (d_decoy - d)^2 / (1 + w).
TEST(EpipolarStereoTest, AmbiguityVarianceAddsTheWeightedSpreadOfAnotherMinimum) {
  const PinholeCamera camera = TestCamera();
  PlanePair pair = MakePlanePair(camera, 1.3, 11, 0.0);
  const int x = 60, y = 60, decoy_disparity = 4;
  cv::Mat decoy = pair.ref(cv::Rect(x - 3, y - 2, 7, 5)) + 1.0f;
  decoy.copyTo(pair.cur(cv::Rect(x - decoy_disparity - 3, y - 2, 7, 5)));
  const ImagePyramid ref(pair.ref, 1), cur(pair.cur, 1);
  const EpipolarGeometry geometry(camera, pair.cur_from_ref);
  MappingOptions options;
  options.sigma_intensity = 1.0;
  options.residual_intensity_noise = false;
  const Eigen::Vector2d pixel(x, y);
  EpipolarPatch patch;
  ASSERT_EQ(MakeEpipolarPatch(ref, geometry, pixel, 0.5, options, &patch), StereoStatus::kOk);
  StereoObservation plain, ambiguous;
  options.ssd_ambiguity_variance = false;
  ASSERT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.0, 1.0, options, &plain),
            StereoStatus::kOk);
  options.ssd_ambiguity_variance = true;
  ASSERT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.0, 1.0, options, &ambiguous),
            StereoStatus::kOk);
  // The parabola through the half-pixel SSDs of the bilinear image moves the match by ~0.1 px.
  EXPECT_NEAR(ambiguous.idepth, 1.0 / 1.3, 0.02);
  EXPECT_EQ(ambiguous.idepth, plain.idepth);
  const double w = std::exp(-5.0 / 4.0);
  const double offset = decoy_disparity / (camera.fx * 0.1) - ambiguous.idepth;
  const double spread = w * offset * offset / (1.0 + w);
  EXPECT_NEAR(ambiguous.idepth_var - plain.idepth_var, spread, 0.02 * spread);
}

TEST(DepthPropagationTest, PlaneDepthIsPropagatedWithInflatedVariance) {
  const PinholeCamera camera = TestCamera();
  cv::Mat image(camera.height, camera.width, CV_8U);
  cv::RNG rng(3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 255);
  const ImagePyramid pyramid(image, 1);
  MappingOptions options;
  options.max_propagation_intensity_diff = 1e9;  // same image: no appearance check
  SemiDenseDepthMap map(camera.width, camera.height);
  map.SelectPixels(pyramid, cv::Mat(), options);
  map.InitializeConstant(0.5, 1e-3, 20);
  // The inlier-ratio evidence travels with the hypothesis.
  for (int i = 0; i < map.num_pixels(); ++i) map.SetEvidence(i, 3.0, 2.0);
  // Move 0.2 m forward: a fronto-parallel plane at 2 m is then at 1.8 m.
  const SE3 new_from_old(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, 0.0, -0.2));
  PropagationStats stats;
  const SemiDenseDepthMap propagated =
      PropagateDepthMap(map, pyramid, pyramid, cv::Mat(), camera, new_from_old, options, &stats);
  ASSERT_GT(stats.propagated, 1000);
  // Engel 2013 Sec. 2.4: d1 = d0 / (1 - t_z d0) with t_z = -0.2 along the optical axis, so
  // d d1 / d d0 = (d1 / d0)^2 and V1 = (d1 / d0)^4 V0 + sigma_p^2.
  const double d1 = 1.0 / 1.8, jacobian = d1 * d1 / (0.5 * 0.5);
  const double v1 = jacobian * jacobian * 1e-3 + options.propagation_var;
  // Every old hypothesis has the same depth and variance, so a new pixel that received k of them
  // (collisions of compatible hypotheses fuse) has exactly V1 / k. The zoom of 2 / 1.8 spreads
  // the old pixels apart, so nearly all receive one: V1 itself, which only the closed form gives
  // (without the (d1/d0)^4 = 1.524 factor V1 would be 1.1e-3 instead of 1.624e-3, a ratio of
  // 1.48 to the expected value; the former upper bound alone let that pass).
  int single = 0, not_v1_over_k = 0, wrong_idepth = 0, wrong_evidence = 0;
  for (int i = 0; i < propagated.num_pixels(); ++i) {
    if (!propagated.valid(i)) continue;
    wrong_idepth += std::abs(propagated.idepth(i) - d1) > 1e-5;
    const double k = v1 / propagated.idepth_var(i);
    // Float storage: ~1e-7 relative.
    not_v1_over_k += std::abs(k - std::round(k)) > 1e-6 || std::round(k) < 1.0;
    single += std::round(k) == 1.0;
    wrong_evidence += propagated.inlier_evidence(i) != 3.f || propagated.outlier_evidence(i) != 2.f;
  }
  EXPECT_EQ(wrong_idepth, 0);
  EXPECT_EQ(not_v1_over_k, 0) << "of " << stats.propagated << "; expected V1 / k, V1 = " << v1;
  EXPECT_EQ(wrong_evidence, 0);
  EXPECT_GE(single, stats.propagated - stats.collisions_fused);
  EXPECT_GT(single, 0.9 * stats.propagated);
}

// The appearance check compares the old keyframe with the new one taken to the old brightness:
// with a new keyframe 1.3x as bright and 12 gray levels darker (float, no clipping) and no
// motion, every hypothesis fails a 5 gray level check without the transfer and passes with it.
TEST(DepthPropagationTest, IntensityCheckUndoesTheNewKeyframesBrightness) {
  const PinholeCamera camera = TestCamera();
  cv::Mat image(camera.height, camera.width, CV_32F);
  cv::RNG rng(4);
  rng.fill(image, cv::RNG::UNIFORM, 60.0, 180.0);
  const ImagePyramid old_keyframe(image, 1);
  cv::Mat brighter;
  image.convertTo(brighter, CV_32F, 1.3, -12.0);
  const ImagePyramid new_keyframe(brighter, 1);
  MappingOptions options;
  options.max_propagation_intensity_diff = 5.0;
  SemiDenseDepthMap map(camera.width, camera.height);
  map.SelectPixels(old_keyframe, cv::Mat(), options);
  map.InitializeConstant(0.5, 1e-3, 20);
  const int hypotheses = map.CountValid();
  ASSERT_GT(hypotheses, 1000);
  PropagationStats plain, transferred;
  PropagateDepthMap(map, old_keyframe, new_keyframe, cv::Mat(), camera, SE3(), options, &plain);
  PropagateDepthMap(map, old_keyframe, new_keyframe, cv::Mat(), camera, SE3(), options,
                    &transferred, AffineBrightness{std::log(1.3), -12.0});
  EXPECT_EQ(plain.propagated, 0);
  EXPECT_EQ(plain.dropped_intensity + plain.dropped_outside + plain.dropped_not_candidate,
            hypotheses);
  EXPECT_EQ(transferred.dropped_intensity, 0);
  EXPECT_EQ(transferred.propagated,
            hypotheses - transferred.dropped_outside - transferred.dropped_not_candidate);
}

// SmoothDepthMap as it was first written (the (2r+1)^2 window of every valid pixel through the
// accessors, two divisions per neighbour visit): the reference the optimised one must reproduce
// bit for bit.
int ReferenceSmoothDepthMap(const SemiDenseDepthMap& in, const MappingOptions& options,
                            SemiDenseDepthMap* out) {
  *out = in;
  const int r = options.regularization_radius;
  const double gate_sq = options.regularization_gate_sigmas * options.regularization_gate_sigmas;
  int smoothed = 0;
  for (int y = 0; y < in.height(); ++y) {
    for (int x = 0; x < in.width(); ++x) {
      const int i = in.Index(x, y);
      if (!in.valid(i)) continue;
      const double d_i = in.idepth(i), v_i = in.idepth_var(i);
      double sum = d_i / v_i, sum_info = 1.0 / v_i;
      int neighbours = 0;
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= in.height()) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if ((dx == 0 && dy == 0) || xx < 0 || xx >= in.width()) continue;
          const int j = in.Index(xx, yy);
          if (!in.valid(j)) continue;
          const double d_j = in.idepth(j), v_j = in.idepth_var(j);
          if ((d_i - d_j) * (d_i - d_j) > gate_sq * (v_i + v_j)) continue;
          sum += d_j / v_j;
          sum_info += 1.0 / v_j;
          ++neighbours;
        }
      }
      if (neighbours > 0) {
        out->SetIdepth(i, sum / sum_info);
        ++smoothed;
      }
    }
  }
  return smoothed;
}

// A random map: 40% of the pixels valid, the four corners included, on two depth layers 1 apart
// with noise of sd 0.05 and variances log-uniform in [1e-4, 1e-1], so that the gate both admits
// and rejects neighbours; the other pixels hold invalidated hypotheses of the same kind.
SemiDenseDepthMap RandomSparseMap(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.05);
  SemiDenseDepthMap map(width, height);
  for (int i = 0; i < map.num_pixels(); ++i) {
    const int x = i % width, y = i / width;
    const bool corner = (x == 0 || x == width - 1) && (y == 0 || y == height - 1);
    const double idepth = (unit(rng) < 0.5 ? 0.5 : 1.5) + noise(rng);
    map.Set(i, idepth, std::pow(10.0, -4.0 + 3.0 * unit(rng)), 1);
    if (!corner && unit(rng) >= 0.4) map.Invalidate(i);
  }
  return map;
}

// Every pixel's validity, inverse depth and variance are identical (exact float comparison).
void ExpectIdenticalMaps(const SemiDenseDepthMap& actual, const SemiDenseDepthMap& expected) {
  ASSERT_EQ(actual.width(), expected.width());
  ASSERT_EQ(actual.height(), expected.height());
  for (int i = 0; i < actual.num_pixels(); ++i) {
    ASSERT_EQ(actual.valid(i), expected.valid(i)) << "pixel " << i;
    ASSERT_EQ(actual.idepth(i), expected.idepth(i)) << "pixel " << i;
    ASSERT_EQ(actual.idepth_var(i), expected.idepth_var(i)) << "pixel " << i;
  }
}

int CountDifferentIdepths(const SemiDenseDepthMap& a, const SemiDenseDepthMap& b) {
  int different = 0;
  for (int i = 0; i < a.num_pixels(); ++i) different += a.idepth(i) != b.idepth(i);
  return different;
}

TEST(DepthRegularizerTest, MatchesTheReferenceBitForBit) {
  // 41x29 with windows of radius 1-3, and 3x2, smaller than every window.
  const std::vector<std::pair<int, int>> sizes = {{41, 29}, {3, 2}};
  for (const auto& [width, height] : sizes) {
    for (int radius = 1; radius <= 3; ++radius) {
      for (const double gate_sigmas : {1.0, 2.0}) {
        SCOPED_TRACE(testing::Message()
                     << width << "x" << height << " r " << radius << " gate " << gate_sigmas);
        MappingOptions options;
        options.regularization_radius = radius;
        options.regularization_gate_sigmas = gate_sigmas;
        const SemiDenseDepthMap map =
            RandomSparseMap(width, height, 7 * radius + static_cast<int>(gate_sigmas));

        SemiDenseDepthMap expected_smoothed;
        const int expected_count = ReferenceSmoothDepthMap(map, options, &expected_smoothed);
        // In one stripe of rows and in three (mapping.num_threads; the 3x2 map leaves one
        // stripe without a row).
        for (const int threads : {1, 3}) {
          options.num_threads = threads;
          SemiDenseDepthMap smoothed;
          EXPECT_EQ(SmoothDepthMap(map, options, &smoothed), expected_count) << threads;
          ExpectIdenticalMaps(smoothed, expected_smoothed);
        }

        if (width < 10) continue;
        // The map exercises what the comparison must catch: smoothing changes most hypotheses
        // and the gate changes many results (dropping it would fail above).
        MappingOptions ungated = options;
        ungated.regularization_gate_sigmas = 1e6;
        SemiDenseDepthMap smoothed_ungated;
        ReferenceSmoothDepthMap(map, ungated, &smoothed_ungated);
        EXPECT_GT(CountDifferentIdepths(expected_smoothed, map), map.CountValid() / 2);
        EXPECT_GT(CountDifferentIdepths(expected_smoothed, smoothed_ungated),
                  map.CountValid() / 10);
      }
    }
  }
}

TEST(DepthRegularizerTest, RemovalAndFillingDoNotDependOnTheStripes) {
  // A sparse map whose every pixel is a candidate: isolated hypotheses to remove and holes
  // among valid neighbours to fill. One stripe of rows is the sequential pass; two and three
  // (mapping.num_threads) must give the same map and counts.
  for (const uint32_t seed : {3u, 4u}) {
    SemiDenseDepthMap map = RandomSparseMap(41, 29, seed);
    for (int i = 0; i < map.num_pixels(); ++i) map.SetCandidate(i, true, -1);
    MappingOptions options;
    options.num_threads = 1;
    SemiDenseDepthMap expected = map;
    const int expected_removed = RemoveIsolatedHypotheses(options, &expected);
    const int expected_filled = FillHoles(options, &expected);
    EXPECT_GT(expected_removed, 10) << seed;
    EXPECT_GT(expected_filled, 100) << seed;
    for (const int threads : {2, 3}) {
      SCOPED_TRACE(testing::Message() << "seed " << seed << " threads " << threads);
      options.num_threads = threads;
      SemiDenseDepthMap actual = map;
      EXPECT_EQ(RemoveIsolatedHypotheses(options, &actual), expected_removed);
      EXPECT_EQ(FillHoles(options, &actual), expected_filled);
      ExpectIdenticalMaps(actual, expected);
    }
  }
}

TEST(DepthMapIoTest, WritesPngAndPly) {
  const PinholeCamera camera = TestCamera();
  SemiDenseDepthMap map(camera.width, camera.height);
  int expected = 0;
  for (int y = 10; y < 20; ++y) {
    for (int x = 10; x < 30; ++x) {
      map.Set(map.Index(x, y), 0.2 + 0.01 * x, 0.01, 20);
      if (x % 2 == 0) {
        map.CountObservation(map.Index(x, y));  // only observed hypotheses go to the PLY
        ++expected;
      }
    }
  }
  const std::string dir = ::testing::TempDir();
  WriteInverseDepthPng(map, dir + "/pldvo_idepth.png");
  const cv::Mat png = cv::imread(dir + "/pldvo_idepth.png", cv::IMREAD_COLOR);
  ASSERT_EQ(png.rows, camera.height);
  EXPECT_EQ(png.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));  // invalid: black
  EXPECT_NE(png.at<cv::Vec3b>(15, 20), cv::Vec3b(0, 0, 0));
  const cv::Mat image(camera.height, camera.width, CV_8U, cv::Scalar(100));
  EXPECT_EQ(WritePointCloudPly(map, image, camera, SE3(), dir + "/pldvo_points.ply"), expected);
  std::ifstream ply(dir + "/pldvo_points.ply");
  std::string line;
  int vertices = -1, data_lines = 0;
  bool header = true;
  while (std::getline(ply, line)) {
    if (header) {
      std::sscanf(line.c_str(), "element vertex %d", &vertices);
      header = line != "end_header";
    } else {
      ++data_lines;
    }
  }
  EXPECT_EQ(vertices, expected);
  EXPECT_EQ(data_lines, expected);
  EXPECT_THROW(WriteInverseDepthPng(map, "/nonexistent_dir/x.png"), std::runtime_error);
}

TEST(DepthMapIoTest, NormalizedObservedDepthHasMedianInverseDepthOne) {
  const PinholeCamera camera = TestCamera();
  SemiDenseDepthMap map(camera.width, camera.height);
  int count = -1;
  EXPECT_TRUE(NormalizedObservedDepth(map, &count).empty());
  EXPECT_EQ(count, 0);
  // Observed inverse depths 0.5, 1, 2 (median 1 -> scaled by 1), then 1, 2, 4 (median 2); an
  // unobserved hypothesis and an observed one at idepth 0 are left out.
  const double idepths[] = {0.5, 1.0, 2.0};
  for (double factor : {1.0, 2.0}) {
    for (int x = 0; x < 3; ++x) {
      map.Set(map.Index(x, 0), factor * idepths[x], 0.01, 20);
      map.CountObservation(map.Index(x, 0));
    }
    map.Set(map.Index(5, 0), 3.0, 0.01, 20);
    map.Set(map.Index(6, 0), 0.0, 0.01, 20);
    map.CountObservation(map.Index(6, 0));
    double median = 0.0;
    const cv::Mat depth = NormalizedObservedDepth(map, &count, &median);
    EXPECT_EQ(count, 3);
    EXPECT_DOUBLE_EQ(median, factor);
    ASSERT_EQ(depth.type(), CV_32F);
    EXPECT_FLOAT_EQ(depth.at<float>(0, 0), 2.f);
    EXPECT_FLOAT_EQ(depth.at<float>(0, 1), 1.f);
    EXPECT_FLOAT_EQ(depth.at<float>(0, 2), 0.5f);
    EXPECT_EQ(depth.at<float>(0, 5), 0.f);
    EXPECT_EQ(depth.at<float>(0, 6), 0.f);
    EXPECT_EQ(cv::countNonZero(depth), 3);
  }
}

}  // namespace
}  // namespace pldvo
