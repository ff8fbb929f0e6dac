// Skipping uninformative SSD searches (mapping.uninformative_search_ratio, docs/mapping.md
// "Photometric stereo"): a valid hypothesis is not searched when even its observation's geometric
// variance exceeds ratio x its variance. Scene: a fronto-parallel plane at 1 m with a blurred
// random texture, seen by a camera translating along x; the keyframe's map starts at the true
// depth with inverse-depth sigma 0.1 1/m.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "tests/backend/translated_plane.h"

namespace pldvo {
namespace {

const PinholeCamera& kCamera = test::kPlaneCamera;
using test::kPlaneDepth;
constexpr int kMargin = test::kPlaneMargin;
constexpr double kPriorSigma = 0.1;  // 1/m: 0.65 px of disparity at 5 cm

cv::Mat ImageAt(const cv::Mat& texture, double baseline) {
  return test::TranslatedPlaneImage(texture, kCamera, kPlaneDepth, kMargin, baseline);
}

DepthMapper MapperAtTruth(const cv::Mat& texture, double ratio) {
  MappingOptions options;
  options.uninformative_search_ratio = ratio;
  options.regularize = false;  // compare the stereo updates alone
  DepthMapper mapper(kCamera, options);
  const cv::Mat depth(kCamera.height, kCamera.width, CV_32F, cv::Scalar(kPlaneDepth));
  mapper.InitializeKeyframeFromDepth(ImageAt(texture, 0.0), EdgeTrace(), depth,
                                     kPriorSigma * kPriorSigma);
  return mapper;
}

// Every search the ratio skips would have shrunk its hypothesis' variance by less than
// 1 / (1 + ratio): the bound is a lower bound of the observation's variance. At a short baseline
// most searches are skipped, at a long one none.
TEST(UninformativeSearchTest, SkippedSearchesWouldNotHaveShrunkTheVariance) {
  constexpr double kRatio = 10.0;
  const cv::Mat texture = test::BlurredNoiseTexture(7);
  for (const double baseline : {0.002, 0.01, 0.02, 0.05}) {
    DepthMapper searched = MapperAtTruth(texture, 0.0);
    DepthMapper skipping = MapperAtTruth(texture, kRatio);
    const SemiDenseDepthMap before = searched.depth_map();
    const cv::Mat image = ImageAt(texture, baseline);
    const SE3 cur_from_ref = test::TranslatedCurFromRef(baseline);
    const FrameUpdateStats all = searched.UpdateWithFrame(image, cur_from_ref, {});
    const FrameUpdateStats some = skipping.UpdateWithFrame(image, cur_from_ref, {});
    EXPECT_EQ(all.ssd_skipped, 0);
    EXPECT_EQ(some.ssd_attempts + some.ssd_skipped, all.ssd_attempts);
    int changed = 0;
    double largest_shrink = 0.0;  // of a skipped pixel's variance by the full update
    for (int i = 0; i < before.num_pixels(); ++i) {
      if (!before.valid(i)) continue;
      const double full = searched.depth_map().idepth_var(i);
      const double kept = skipping.depth_map().idepth_var(i);
      if (full == kept) continue;
      ++changed;
      EXPECT_EQ(kept, before.idepth_var(i)) << "pixel " << i;
      largest_shrink = std::max(largest_shrink, 1.0 - full / before.idepth_var(i));
    }
    std::printf(
        "baseline %.3f m: %lld searches, %lld skipped, %d variances differ, largest shrink "
        "%.4f (bound %.4f)\n",
        baseline, static_cast<long long>(all.ssd_attempts),
        static_cast<long long>(some.ssd_skipped), changed, largest_shrink, 1.0 / (1.0 + kRatio));
    EXPECT_LE(largest_shrink, 1.0 / (1.0 + kRatio) + 1e-6);
    if (baseline < 0.005) {
      EXPECT_GT(some.ssd_skipped, all.ssd_attempts / 2);
    }
    if (baseline > 0.04) {
      EXPECT_EQ(some.ssd_skipped, 0);
    }
  }
}

// A negative or infinite ratio is a configuration error.
TEST(UninformativeSearchTest, TheRatioMustBeFiniteAndNonNegative) {
  MappingOptions options;
  EXPECT_EQ(options.Check(), "");
  for (const double bad : {-1.0, std::numeric_limits<double>::infinity()}) {
    options.uninformative_search_ratio = bad;
    EXPECT_NE(options.Check().find("uninformative_search_ratio"), std::string::npos);
  }
}

}  // namespace
}  // namespace pldvo
