// An SSD search whose best step is an end of the prior interval (mapping.ssd_interval_end,
// docs/mapping.md "Photometric stereo"): on low-contrast step edges the 5-sample SSD
// falls towards the true match, so a hypothesis whose interval misses it gets the interval's end
// as a match, fuses it and narrows its interval around a wrong depth. Scene: a fronto-parallel
// plane at 1 m of vertical stripes 20 px wide (gray 100 / 130, blurred with sigma 1) seen by a
// camera translating along x.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/epipolar_stereo.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "tests/backend/translated_plane.h"

namespace pldvo {
namespace {

const PinholeCamera& kCamera = test::kPlaneCamera;
using test::kPlaneDepth;
constexpr int kMargin = test::kPlaneMargin;

// The stripes, wider than the image by kMargin on each side (CV_32F).
cv::Mat StripeTexture() {
  cv::Mat texture(kCamera.height + 2 * kMargin, kCamera.width + 2 * kMargin, CV_32F);
  for (int x = 0; x < texture.cols; ++x) {
    texture.col(x).setTo((x / 20) % 2 == 0 ? 100.0f : 130.0f);
  }
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.0);
  return texture;
}

cv::Mat ImageAt(const cv::Mat& texture, double baseline) {
  return test::TranslatedPlaneImage(texture, kCamera, kPlaneDepth, kMargin, baseline);
}

SE3 CurFromRef(double baseline) { return test::TranslatedCurFromRef(baseline); }

// One edge pixel, baseline 0.1 m (13 px of disparity at the true inverse depth 1): an interval
// that ends short of the truth has its best SSD at that end.
TEST(SsdIntervalEndTest, SearchReportsAMinimumAtAnOpenEndOfTheInterval) {
  const cv::Mat texture = StripeTexture();
  const ImagePyramid ref(ImageAt(texture, 0.0), 1), cur(ImageAt(texture, 0.1), 1);
  const EpipolarGeometry geometry(kCamera, CurFromRef(0.1));
  const Eigen::Vector2d pixel(120.0 - kMargin, 60.0);  // next to the edge at texture x = 119.5
  MappingOptions options;
  EpipolarPatch patch;
  ASSERT_EQ(MakeEpipolarPatch(ref, geometry, pixel, 0.7, options, &patch), StereoStatus::kOk);
  StereoObservation observation;
  // Engel 2013 (accept): the interval [0.5, 0.85] 1/m (6.5 to 11.05 px) misses the truth, and
  // its near end is reported as the match (measured 0.846).
  ASSERT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.5, 0.85, options, &observation),
            StereoStatus::kOk);
  EXPECT_NEAR(observation.idepth, 0.85, 0.01);
  options.ssd_interval_end = MappingOptions::IntervalEndMinimum::kSkip;
  EXPECT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.5, 0.85, options, &observation),
            StereoStatus::kIntervalEnd);
  // An interval around the truth finds it.
  ASSERT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.5, 1.5, options, &observation),
            StereoStatus::kOk);
  EXPECT_NEAR(observation.idepth, 1.0, 0.02);
  // An end at the global bound max_idepth is a minimum: nothing lies beyond it.
  options.max_idepth = 0.85;
  ASSERT_EQ(SearchEpipolarSsd(cur, geometry, patch, pixel, 0.5, 0.85, options, &observation),
            StereoStatus::kOk);
  EXPECT_NEAR(observation.idepth, 0.85, 0.01);
}

// The keyframe's map starts at depth `prior_depth` with inverse-depth sigma 0.05 and is updated
// with ten frames at baselines 0.02 ... 0.2 m. Returns the median relative inverse-depth error
// of the valid hypotheses and their count.
double MedianErrorAfterTenFrames(MappingOptions::IntervalEndMinimum rule, double prior_depth,
                                 int* valid) {
  MappingOptions options;
  options.ssd_interval_end = rule;
  const cv::Mat texture = StripeTexture();
  DepthMapper mapper(kCamera, options);
  const cv::Mat depth(kCamera.height, kCamera.width, CV_32F, cv::Scalar(prior_depth));
  mapper.InitializeKeyframeFromDepth(ImageAt(texture, 0.0), EdgeTrace(), depth, 0.05 * 0.05);
  for (int k = 1; k <= 10; ++k) {
    mapper.UpdateWithFrame(ImageAt(texture, 0.02 * k), CurFromRef(0.02 * k), {});
  }
  const SemiDenseDepthMap& map = mapper.depth_map();
  std::vector<double> errors;
  for (int i = 0; i < map.num_pixels(); ++i) {
    if (map.valid(i)) errors.push_back(std::abs(map.idepth(i) * kPlaneDepth - 1.0));
  }
  *valid = static_cast<int>(errors.size());
  if (errors.empty()) return 1.0;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

// A map 40% too far (inverse depth 0.714, the truth 5.7 sigma away): accepting the interval's
// end creeps towards the truth while the variance shrinks, and the whole map stays wrong; as
// outliers the contradicted hypotheses are dropped, and the ones a full-range search finds
// again (the stripes repeat every 40 px: most such searches are ambiguous) are right.
TEST(SsdIntervalEndTest, ContradictedHypothesesAreDroppedAndFoundAgain) {
  using Rule = MappingOptions::IntervalEndMinimum;
  int valid_accept = 0, valid_skip = 0, valid_outlier = 0;
  const double accept = MedianErrorAfterTenFrames(Rule::kAccept, 1.4, &valid_accept);
  const double skip = MedianErrorAfterTenFrames(Rule::kSkip, 1.4, &valid_skip);
  const double outlier = MedianErrorAfterTenFrames(Rule::kOutlier, 1.4, &valid_outlier);
  std::printf("median relative error: accept %.3f (%d), skip %.3f (%d), outlier %.3f (%d)\n",
              accept, valid_accept, skip, valid_skip, outlier, valid_outlier);
  // Measured: accept 0.227 (1596 hypotheses), skip 0.274 (1596), outlier 0.000 (228).
  EXPECT_GT(accept, 0.15);
  EXPECT_GT(skip, 0.15);
  EXPECT_LT(outlier, 0.01);
  EXPECT_GT(valid_outlier, 100);
}

// A map at the right depth: no search ends at its interval's end, and the rules agree.
TEST(SsdIntervalEndTest, RightHypothesesAreKept) {
  using Rule = MappingOptions::IntervalEndMinimum;
  int valid_accept = 0, valid_outlier = 0;
  const double accept = MedianErrorAfterTenFrames(Rule::kAccept, kPlaneDepth, &valid_accept);
  const double outlier = MedianErrorAfterTenFrames(Rule::kOutlier, kPlaneDepth, &valid_outlier);
  std::printf("median relative error: accept %.4f (%d), outlier %.4f (%d)\n", accept, valid_accept,
              outlier, valid_outlier);
  EXPECT_LT(accept, 0.01);
  EXPECT_LT(outlier, 0.01);
  EXPECT_EQ(valid_outlier, valid_accept);
}

// CountOutlier under each outlier model: validity 20 - 5 per count drops the hypothesis at the 4th;
// the inlier-ratio filter's Beta(10, 10) prior falls below the ratio 0.1 at the 81st outlier
// (10 / (20 + n) < 0.1 for n > 80). The depth is untouched.
TEST(SsdIntervalEndTest, CountOutlierFollowsTheOutlierModel) {
  for (const auto model : {MappingOptions::OutlierModel::kValidityCounter,
                           MappingOptions::OutlierModel::kInlierRatio}) {
    MappingOptions options;
    options.outlier_model = model;
    SemiDenseDepthMap map(1, 1);
    map.Set(0, 0.5, 0.01, options.validity_initial);
    int counts = 0;
    while (map.valid(0) && counts < 1000) {
      EXPECT_EQ(map.idepth(0), 0.5f);
      map.CountOutlier(0, options);
      ++counts;
    }
    EXPECT_EQ(counts, model == MappingOptions::OutlierModel::kValidityCounter ? 4 : 81);
  }
}

}  // namespace
}  // namespace pldvo
