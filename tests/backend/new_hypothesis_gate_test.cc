// New hypotheses only from precise observations (mapping.new_hypothesis_max_relative_sigma) or
// fused with a prior at the map's mean (mapping.new_hypothesis_prior_relative_sigma;
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

DepthMapper HalfMappedKeyframe(const cv::Mat& texture, double ratio, double prior = 0.0) {
  MappingOptions options;
  options.new_hypothesis_max_relative_sigma = ratio;
  options.new_hypothesis_prior_relative_sigma = prior;
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

// With a prior (mapping.new_hypothesis_prior_relative_sigma p), every new hypothesis is the
// inverse-variance fusion of the same observation with N(mean, (p mean)^2): created where the
// observation alone creates, at prior + w (observation - prior) with variance w V_obs, w = p^2
// mean^2 / (p^2 mean^2 + V_obs). At 2 mm that pulls the near-side draws most of the way back (the
// plane is at the map's mean here, the prior's best case; the exact fusion is what the test holds).
TEST(NewHypothesisGateTest, APriorAtTheMeanIsFusedIntoEveryNewHypothesis) {
  constexpr double kPrior = 1.0;
  const cv::Mat texture = test::BlurredNoiseTexture(11);
  for (const double baseline : {0.002, 0.05}) {
    DepthMapper alone = HalfMappedKeyframe(texture, 0.0);
    DepthMapper fused = HalfMappedKeyframe(texture, 0.0, kPrior);
    const SemiDenseDepthMap before = alone.depth_map();
    const double mean = MeanInverseDepth(before);
    ASSERT_DOUBLE_EQ(mean, 1.0 / kPlaneDepth);
    const cv::Mat image = ImageAt(texture, baseline, 2);
    const SE3 cur_from_ref = test::TranslatedCurFromRef(baseline);
    const FrameUpdateStats a = alone.UpdateWithFrame(image, cur_from_ref, {});
    const FrameUpdateStats b = fused.UpdateWithFrame(image, cur_from_ref, {});
    ASSERT_GT(a.created, 1000);
    EXPECT_EQ(b.created, a.created);
    EXPECT_EQ(b.not_created, 0);
    const double prior_var = kPrior * kPrior * mean * mean;
    std::vector<double> errors_alone, errors_fused;
    for (int i = 0; i < before.num_pixels(); ++i) {
      if (before.valid(i) || !alone.depth_map().valid(i)) continue;
      ASSERT_TRUE(fused.depth_map().valid(i));
      const double obs = alone.depth_map().idepth(i);
      const double obs_var = alone.depth_map().idepth_var(i);
      const double w = prior_var / (prior_var + obs_var);
      EXPECT_NEAR(fused.depth_map().idepth(i), mean + w * (obs - mean), 1e-5 * (1.0 + obs));
      EXPECT_NEAR(fused.depth_map().idepth_var(i), w * obs_var, 1e-5 * obs_var);
      errors_alone.push_back(std::abs(obs - 1.0 / kPlaneDepth));
      errors_fused.push_back(std::abs(fused.depth_map().idepth(i) - 1.0 / kPlaneDepth));
    }
    std::printf("baseline %.3f m: median |error| %.3f alone, %.3f with the prior\n", baseline,
                Median(errors_alone), Median(errors_fused));
    if (baseline < 0.005) {
      EXPECT_LT(Median(errors_fused), 0.5 * Median(errors_alone));
    } else {
      EXPECT_LT(Median(errors_fused), 0.03);  // precise observations keep nearly all their weight
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

// A negative or infinite ratio or prior is a configuration error.
TEST(NewHypothesisGateTest, TheRatioAndThePriorMustBeFiniteAndNonNegative) {
  MappingOptions options;
  EXPECT_EQ(options.Check(), "");
  for (const double bad : {-1.0, std::numeric_limits<double>::infinity()}) {
    options.new_hypothesis_max_relative_sigma = bad;
    EXPECT_NE(options.Check().find("new_hypothesis_max_relative_sigma"), std::string::npos);
    options.new_hypothesis_max_relative_sigma = 0.0;
    options.new_hypothesis_prior_relative_sigma = bad;
    EXPECT_NE(options.Check().find("new_hypothesis_prior_relative_sigma"), std::string::npos);
    options.new_hypothesis_prior_relative_sigma = 0.0;
  }
}

}  // namespace
}  // namespace pldvo
