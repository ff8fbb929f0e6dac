// RefineSegmentsToEdges on a rendered straight step edge with a known sub-pixel position:
// a segment placed off the edge and turned is refitted onto it; segments without an edge within
// the search radius, or whose refit would turn them too far, are kept.
#include "frontend/line_refiner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "frontend/line_detector.h"

namespace pldvo {
namespace {

// The edge: the line through kEdgePoint with unit normal (cos kEdgeAngle, sin kEdgeAngle);
// intensity 60 on its negative side, 180 on the positive side, each pixel the box-filtered
// step (area coverage of the pixel across the edge), plus Gaussian noise of 1 gray level.
const Eigen::Vector2d kEdgePoint(100.3, 75.6);
constexpr double kEdgeAngle = 20.0 * M_PI / 180.0;
const Eigen::Vector2d kNormal(std::cos(kEdgeAngle), std::sin(kEdgeAngle));
const Eigen::Vector2d kAlong(-kNormal.y(), kNormal.x());

cv::Mat StepEdgeImage() {
  cv::Mat image(150, 200, CV_8U);
  cv::RNG rng(5);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      // Coverage of the unit pixel by the positive side, from 8 x 8 sub-samples.
      int covered = 0;
      for (int j = 0; j < 8; ++j) {
        for (int i = 0; i < 8; ++i) {
          const Eigen::Vector2d p(x - 0.5 + (i + 0.5) / 8.0, y - 0.5 + (j + 0.5) / 8.0);
          covered += kNormal.dot(p - kEdgePoint) > 0.0;
        }
      }
      const double value = 60.0 + 120.0 * covered / 64.0 + rng.gaussian(1.0);
      image.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(value);
    }
  }
  return image;
}

double DistanceToEdge(const Eigen::Vector2d& p) { return kNormal.dot(p - kEdgePoint); }

// A 100 px segment along the edge, moved by `offset` px along its normal and turned by
// `turn_deg` about its midpoint.
LineSegment SegmentNearEdge(double offset, double turn_deg) {
  const double turn = turn_deg * M_PI / 180.0;
  const Eigen::Vector2d along =
      std::cos(turn) * kAlong + std::sin(turn) * kNormal;  // turned direction
  const Eigen::Vector2d mid = kEdgePoint + offset * kNormal;
  return MakeLineSegment(mid - 50.0 * along, mid + 50.0 * along, 0, 0.5);
}

TEST(LineRefinerTest, SegmentOffTheEdgeIsRefittedOntoIt) {
  const cv::Mat image = StepEdgeImage();
  LineRefinerOptions options;
  double worst = 0.0;
  for (const double offset : {-1.3, -0.4, 0.0, 0.8, 1.4}) {
    for (const double turn : {-1.0, 0.0, 1.5}) {
      std::vector<LineSegment> segments = {SegmentNearEdge(offset, turn)};
      const LineSegment before = segments[0];
      ASSERT_EQ(RefineSegmentsToEdges(image, options, 0.5, &segments), 1);
      const LineSegment& after = segments[0];
      EXPECT_LT(std::abs(DistanceToEdge(after.start)), 0.02) << offset << " " << turn;
      EXPECT_LT(std::abs(DistanceToEdge(after.end)), 0.02) << offset << " " << turn;
      worst = std::max(
          {worst, std::abs(DistanceToEdge(after.start)), std::abs(DistanceToEdge(after.end))});
      // Same extent and direction, Sigma_l anew for its endpoints.
      EXPECT_NEAR(after.length, before.length, 2.0);
      EXPECT_GT(after.direction().dot(before.direction()), 0.99);
      EXPECT_TRUE(
          after.line_cov.isApprox(MakeLineSegment(after.start, after.end, 0, 0.5).line_cov, 1e-12));
    }
  }
  std::printf("largest endpoint distance to the edge after the refit: %.3f px\n", worst);
}

TEST(LineRefinerTest, SegmentWithoutAnEdgeInReachIsKept) {
  const cv::Mat image = StepEdgeImage();
  LineRefinerOptions options;  // search radius 2 px
  for (const double offset : {-4.0, 5.0, 30.0}) {
    std::vector<LineSegment> segments = {SegmentNearEdge(offset, 0.0)};
    const LineSegment before = segments[0];
    EXPECT_EQ(RefineSegmentsToEdges(image, options, 0.5, &segments), 0) << offset;
    EXPECT_EQ(segments[0].start, before.start);
    EXPECT_EQ(segments[0].end, before.end);
  }
  // Crossing the edge at 10 deg: the refit would turn it by 10 deg (> max_angle_deg 2).
  std::vector<LineSegment> crossing = {SegmentNearEdge(0.0, 10.0)};
  EXPECT_EQ(RefineSegmentsToEdges(image, options, 0.5, &crossing), 0);
  // A segment shorter than three profiles is kept.
  std::vector<LineSegment> short_segment = {
      MakeLineSegment(kEdgePoint - 2.0 * kAlong, kEdgePoint + 2.0 * kAlong, 0, 0.5)};
  EXPECT_EQ(RefineSegmentsToEdges(image, options, 0.5, &short_segment), 0);
}

TEST(LineRefinerTest, OctaveScalesTheNewCovarianceAndWrongImagesThrow) {
  const cv::Mat image = StepEdgeImage();
  LineSegment segment = SegmentNearEdge(0.6, 0.5);
  segment.octave = 1;
  std::vector<LineSegment> segments = {segment};
  ASSERT_EQ(RefineSegmentsToEdges(image, LineRefinerOptions(), 0.5, &segments), 1);
  EXPECT_EQ(segments[0].octave, 1);
  EXPECT_TRUE(segments[0].line_cov.isApprox(
      MakeLineSegment(segments[0].start, segments[0].end, 1, 1.0).line_cov, 1e-12));
  cv::Mat float_image;
  image.convertTo(float_image, CV_32F);
  EXPECT_THROW(RefineSegmentsToEdges(float_image, LineRefinerOptions(), 0.5, &segments),
               std::invalid_argument);
  LineRefinerOptions bad;
  bad.search_radius_px = 9;
  EXPECT_FALSE(bad.Check().empty());
}

}  // namespace
}  // namespace pldvo
