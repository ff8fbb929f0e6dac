// The mapping evaluation's statistics (experiments/evaluation/mapping_ground_truth.h): on
// hypotheses drawn from their own predicted Gaussian the NEES decomposition must give its chi^2(1)
// values, and the continuity mask must cut exactly around depth steps.
#include "experiments/evaluation/mapping_ground_truth.h"

#include <gtest/gtest.h>

#include <random>

namespace pldvo {
namespace {

// Every pixel a candidate with GT inverse depth 0.5 (a fronto-parallel plane at 2 m).
SemiDenseDepthMap AllCandidates(int width, int height) {
  SemiDenseDepthMap map(width, height);
  for (int i = 0; i < map.num_pixels(); ++i) map.SetCandidate(i, true, -1);
  return map;
}

TEST(EvaluateDepthMapTest, ConsistentSamplesGiveChiSquareStatistics) {
  // Monte Carlo: d_i ~ N(d_gt, V_i) with V_i spread over two decades. Expected (chi^2(1)): mean
  // NEES 1, median 0.455, 95.4% within 2 sigma, 0.1% above 10.83, bulk mean 0.988.
  SemiDenseDepthMap map = AllCandidates(400, 250);
  const cv::Mat gt(250, 400, CV_32F, cv::Scalar(0.5f));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> log_sigma(std::log(1e-3), std::log(1e-1));
  std::normal_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < map.num_pixels(); ++i) {
    const double sigma = std::exp(log_sigma(rng));
    map.Set(i, 0.5 + sigma * unit(rng), sigma * sigma, 20);
    map.CountObservation(i);
  }
  const DepthErrorStats stats = EvaluateDepthMap(map, gt, cv::Mat());
  ASSERT_EQ(stats.count, 100000);
  EXPECT_NEAR(stats.mean_nees, 1.0, 0.02);
  EXPECT_NEAR(stats.median_nees, 0.455, 0.015);
  EXPECT_NEAR(stats.within_2sigma, 0.954, 0.003);
  EXPECT_NEAR(stats.gross_fraction, 0.001, 0.0005);
  EXPECT_NEAR(stats.bulk_mean_nees, 0.988, 0.02);
}

TEST(EvaluateDepthMapTest, GrossErrorsAreSeparatedFromTheBulk) {
  // 5% of the hypotheses 10 sigma off: the mean NEES explodes (~6), the bulk stays at 0.988.
  SemiDenseDepthMap map = AllCandidates(200, 200);
  const cv::Mat gt(200, 200, CV_32F, cv::Scalar(0.5f));
  std::mt19937 rng(5);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double sigma = 0.01;
  for (int i = 0; i < map.num_pixels(); ++i) {
    const double error = i % 20 == 0 ? 10.0 * sigma : sigma * unit(rng);
    map.Set(i, 0.5 + error, sigma * sigma, 20);
    map.CountObservation(i);
  }
  const DepthErrorStats stats = EvaluateDepthMap(map, gt, cv::Mat());
  EXPECT_GT(stats.mean_nees, 5.0);
  EXPECT_NEAR(stats.gross_fraction, 0.05 + 0.95 * 0.001, 0.002);
  EXPECT_NEAR(stats.bulk_mean_nees, 0.988, 0.05);
}

TEST(EvaluateDepthMapTest, MonocularMapIsComparedAfterItsMedianScale) {
  // A consistent map (as above) of a scene at twice the true scale: inverse depths and sigmas
  // halved. MedianInverseDepthRatio recovers the factor 2, and the scaled evaluation gives the
  // statistics of the metric map; unscaled, every pixel is off by half its inverse depth.
  SemiDenseDepthMap metric = AllCandidates(200, 200), half = AllCandidates(200, 200);
  cv::Mat gt(200, 200, CV_32F);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> idepth(0.3, 2.0);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < metric.num_pixels(); ++i) {
    const double d_gt = idepth(rng), sigma = 0.01 * d_gt, d = d_gt + sigma * unit(rng);
    gt.at<float>(i / 200, i % 200) = static_cast<float>(d_gt);
    metric.Set(i, d, sigma * sigma, 20);
    half.Set(i, d / 2.0, sigma * sigma / 4.0, 20);
    metric.CountObservation(i);
    half.CountObservation(i);
  }
  EXPECT_NEAR(MedianInverseDepthRatio(metric, gt), 1.0, 1e-3);
  const double scale = MedianInverseDepthRatio(half, gt);
  EXPECT_NEAR(scale, 2.0, 2e-3);
  const DepthErrorStats expected = EvaluateDepthMap(metric, gt, cv::Mat());
  const DepthErrorStats aligned = EvaluateDepthMap(half, gt, cv::Mat(), true, scale);
  EXPECT_NEAR(aligned.mean_nees, expected.mean_nees, 0.02);
  EXPECT_NEAR(aligned.median_rel_error, expected.median_rel_error, 5e-4);
  EXPECT_NEAR(aligned.within_2sigma, expected.within_2sigma, 0.005);
  EXPECT_NEAR(EvaluateDepthMap(half, gt, cv::Mat()).median_rel_error, 0.5, 0.01);
  // Hypotheses without a stereo observation are left out of the ratio.
  SemiDenseDepthMap unobserved = AllCandidates(200, 200);
  unobserved.Set(0, 1.0, 0.01, 20);
  EXPECT_EQ(MedianInverseDepthRatio(unobserved, gt), 0.0);
}

TEST(ContinuousDepthMaskTest, CutsAroundStepsAndKeepsSlantedPlanes) {
  // Left half: a plane slanted 60 degrees (relative idepth step per pixel ~0.6%); right half: 10%
  // further away; a hole of no depth at the bottom-left.
  cv::Mat gt(60, 80, CV_32F);
  for (int y = 0; y < gt.rows; ++y) {
    for (int x = 0; x < gt.cols; ++x) {
      gt.at<float>(y, x) = x < 40 ? 0.5f * (1.0f + 0.006f * x) : 0.5f / 1.1f;
    }
  }
  gt.at<float>(55, 10) = 0.f;
  const cv::Mat mask = ContinuousDepthMask(gt, 3, 0.02);
  ASSERT_EQ(mask.type(), CV_8U);
  for (int x = 0; x < gt.cols; ++x) {
    // Step between columns 39 and 40: columns 36..43 are cut, the others kept (row 20).
    const bool near_step = x >= 36 && x <= 43;
    EXPECT_EQ(mask.at<uint8_t>(20, x), near_step ? 0 : 255) << "x = " << x;
  }
  // The hole and its 4-neighbours' surroundings: (55, 10) +- 4 is cut, (45, 10) is kept.
  EXPECT_EQ(mask.at<uint8_t>(55, 10), 0);
  EXPECT_EQ(mask.at<uint8_t>(51, 10), 0);
  EXPECT_EQ(mask.at<uint8_t>(45, 10), 255);
  EXPECT_THROW(ContinuousDepthMask(cv::Mat(4, 4, CV_8U), 3, 0.02), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
