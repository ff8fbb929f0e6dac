// New hypotheses only from precise observations (mapping.new_hypothesis_max_relative_sigma,
// docs/mapping.md "Photometric stereo"). Scene: a fronto-parallel plane at 1 m with a blurred
// random texture, seen by a camera translating along x; the keyframe's map holds the true depth
// on the left half of the image (mean inverse depth 1 1/m) and nothing on the right half, whose
// pixels search the whole range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "core/statistics.h"
#include "tests/backend/translated_plane.h"

namespace pldvo {
namespace {

const PinholeCamera& kCamera = test::kPlaneCamera;
using test::kPlaneDepth;
constexpr int kMargin = test::kPlaneMargin;

// The image at `baseline` with Gaussian noise of 2 gray levels (seeded by `seed`).
cv::Mat ImageAt(const cv::Mat& texture, double baseline, int seed) {
  cv::Mat image = test::TranslatedPlaneImage(texture, kCamera, kPlaneDepth, kMargin, baseline);
  cv::Mat noise(image.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
  return image + noise;
}

DepthMapper HalfMappedKeyframe(const cv::Mat& texture, double ratio) {
  MappingOptions options;
  options.new_hypothesis_max_relative_sigma = ratio;
  options.regularize = false;  // compare the stereo updates alone
  DepthMapper mapper(kCamera, options);
  cv::Mat depth(kCamera.height, kCamera.width, CV_32F, cv::Scalar(0.0f));
  depth.colRange(0, kCamera.width / 2).setTo(kPlaneDepth);
  mapper.InitializeKeyframeFromDepth(ImageAt(texture, 0.0, 1), EdgeTrace(), depth, 0.01);
  return mapper;
}

// The gate creates exactly the hypotheses whose observation sigma is at most ratio x the mean
// inverse depth (1 1/m here), from the same searches. At a 2 mm baseline the whole range spans a
// pixel or two, the noisy searches land anywhere on it and the gate keeps none of them; the ones
// it drops are far from the truth. At 5 cm most are kept, precise.
TEST(NewHypothesisGateTest, OnlyPreciseObservationsCreateHypotheses) {
  constexpr double kRatio = 0.5;
  const cv::Mat texture = test::BlurredNoiseTexture(11);
  for (const double baseline : {0.002, 0.05}) {
    DepthMapper always = HalfMappedKeyframe(texture, 0.0);
    DepthMapper gated = HalfMappedKeyframe(texture, kRatio);
    ASSERT_DOUBLE_EQ(MeanInverseDepth(always.depth_map()), 1.0 / kPlaneDepth);
    const SemiDenseDepthMap before = always.depth_map();
    const cv::Mat image = ImageAt(texture, baseline, 2);
    const SE3 cur_from_ref = test::TranslatedCurFromRef(baseline);
    const FrameUpdateStats all = always.UpdateWithFrame(image, cur_from_ref, {});
    const FrameUpdateStats some = gated.UpdateWithFrame(image, cur_from_ref, {});
    EXPECT_EQ(all.not_created, 0);
    EXPECT_EQ(some.created + some.not_created, all.created);
    std::vector<double> kept_errors, dropped_errors, dropped_signed;
    for (int i = 0; i < before.num_pixels(); ++i) {
      if (before.valid(i) || !always.depth_map().valid(i)) continue;
      const double sigma = std::sqrt(always.depth_map().idepth_var(i));
      const double signed_error = always.depth_map().idepth(i) - 1.0 / kPlaneDepth;
      const bool kept = sigma <= kRatio / kPlaneDepth;
      EXPECT_EQ(gated.depth_map().valid(i), kept) << "pixel " << i << " sigma " << sigma;
      (kept ? kept_errors : dropped_errors).push_back(std::abs(signed_error));
      if (!kept) dropped_signed.push_back(signed_error);
    }
    std::printf(
        "baseline %.3f m: %lld created without the gate, %lld with it; median |error| %.3f kept, "
        "%.3f dropped (signed %+.3f)\n",
        baseline, static_cast<long long>(all.created), static_cast<long long>(some.created),
        kept_errors.empty() ? 0.0 : Median(kept_errors),
        dropped_errors.empty() ? 0.0 : Median(dropped_errors),
        dropped_signed.empty() ? 0.0 : Median(dropped_signed));
    ASSERT_GT(all.created, 1000);
    if (baseline < 0.005) {
      EXPECT_EQ(some.created, 0);
      ASSERT_FALSE(dropped_errors.empty());
      EXPECT_GT(Median(dropped_errors), 0.3);
    } else {
      // Only pixels whose gradient nearly crosses the epipolar line stay uncertain.
      EXPECT_GT(some.created, all.created / 2);
      EXPECT_LT(Median(kept_errors), 0.03);
    }
  }
}

// A map without hypotheses has no scale to compare with: it creates as without the gate.
TEST(NewHypothesisGateTest, AnEmptyMapCreatesAsWithoutTheGate) {
  const cv::Mat texture = test::BlurredNoiseTexture(11);
  MappingOptions options;
  options.regularize = false;
  const cv::Mat no_depth(kCamera.height, kCamera.width, CV_32F, cv::Scalar(0.0f));
  DepthMapper always(kCamera, options);
  options.new_hypothesis_max_relative_sigma = 0.5;
  DepthMapper gated(kCamera, options);
  always.InitializeKeyframeFromDepth(ImageAt(texture, 0.0, 1), EdgeTrace(), no_depth, 0.01);
  gated.InitializeKeyframeFromDepth(ImageAt(texture, 0.0, 1), EdgeTrace(), no_depth, 0.01);
  const cv::Mat image = ImageAt(texture, 0.002, 2);
  const SE3 cur_from_ref = test::TranslatedCurFromRef(0.002);
  const FrameUpdateStats all = always.UpdateWithFrame(image, cur_from_ref, {});
  const FrameUpdateStats some = gated.UpdateWithFrame(image, cur_from_ref, {});
  EXPECT_GT(all.created, 1000);
  EXPECT_EQ(some.created, all.created);
  EXPECT_EQ(some.not_created, 0);
}

// A negative or infinite ratio is a configuration error.
TEST(NewHypothesisGateTest, TheRatioMustBeFiniteAndNonNegative) {
  MappingOptions options;
  EXPECT_EQ(options.Check(), "");
  for (const double bad : {-1.0, std::numeric_limits<double>::infinity()}) {
    options.new_hypothesis_max_relative_sigma = bad;
    EXPECT_NE(options.Check().find("new_hypothesis_max_relative_sigma"), std::string::npos);
  }
}

}  // namespace
}  // namespace pldvo
