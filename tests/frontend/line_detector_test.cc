// LineDetector on a supersampled (exactly anti-aliased) rectangle: every side is found by each
// method on each octave, endpoints sit on the true edge to sub-pixel accuracy (LSD, after the
// 0.5 / scale - 0.5 correction) or pixel accuracy (EDLines, FLD: integer edge pixels), and
// every segment is oriented with the brighter side along its normal.
#include "frontend/line_detector.h"

#include <gtest/gtest.h>

#include <iostream>
#include <opencv2/imgproc.hpp>

#include "tests/random_texture.h"

namespace pldvo {
namespace {

// A 640x480 image, background 60, rectangle 180 with edges at x = 100.25, 400.25 and
// y = 120.75, 330.75 (pixel centres at integers), rendered at 8x and area-averaged.
cv::Mat RectangleImage() {
  const int ss = 8;
  cv::Mat big(480 * ss, 640 * ss, CV_8U, cv::Scalar(60));
  // Big pixel X covers [X, X + 1) / ss in left-edge coordinates, i.e. x = (X / ss) - 0.5.
  cv::rectangle(big, cv::Point(806, 970), cv::Point(3205, 2649), cv::Scalar(180), cv::FILLED);
  cv::Mat image;
  cv::resize(big, image, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
  return image;
}

struct Case {
  LineDetectorOptions::Method method;
  int octave;
  double tolerance_px;  // endpoint distance to the true edge line
};

class LineDetectorRectangle : public ::testing::TestWithParam<Case> {};

TEST_P(LineDetectorRectangle, FindsEverySideWithPolarity) {
  const Case c = GetParam();
  LineDetectorOptions options;
  options.method = c.method;
  options.first_octave = c.octave;
  options.num_octaves = 1;
  LineDetector detector(options);
  const std::vector<LineSegment> segments = detector.Detect(BuildOctaves(RectangleImage(), 2));
  // Sides as (point on the edge, direction); the inside (brighter) is towards the centre.
  const Eigen::Vector2d centre(250.25, 225.75);
  const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> sides = {
      {{100.25, 0}, {0, 1}}, {{400.25, 0}, {0, 1}}, {{0, 120.75}, {1, 0}}, {{0, 330.75}, {1, 0}}};
  for (const auto& [point, dir] : sides) {
    int found = 0;
    for (const LineSegment& s : segments) {
      const Eigen::Vector2d n(-dir.y(), dir.x());
      const double d0 = n.dot(s.start - point), d1 = n.dot(s.end - point);
      if (std::abs(d0) > 3.0 || std::abs(d1) > 3.0) continue;
      ++found;
      EXPECT_LE(std::abs(d0), c.tolerance_px);
      EXPECT_LE(std::abs(d1), c.tolerance_px);
      EXPECT_GT(s.length, 150.0);  // the shortest side is 210 px
      // Polarity: the normal points into the bright rectangle.
      EXPECT_GT(s.normal().dot(centre - s.midpoint()), 0.0);
      EXPECT_NEAR(s.line.head<2>().norm(), 1.0, 1e-12);
      EXPECT_NEAR(s.SignedDistance(s.start), 0.0, 1e-9);
      EXPECT_EQ(s.octave, c.octave);
    }
    EXPECT_GE(found, 1) << "side through " << point.transpose() << " not found";
  }
}

// Tolerances: LSD measured 0.05 px at both octaves after the offset correction (0.15 px allows
// for the octave-1 LSD noise ~2x); EDLines and FLD fit integer edge pixels, so the true edge
// between two pixels is up to 0.5 px away (x 2 at octave 1).
INSTANTIATE_TEST_SUITE_P(Methods, LineDetectorRectangle,
                         ::testing::Values(Case{LineDetectorOptions::Method::kLsd, 0, 0.15},
                                           Case{LineDetectorOptions::Method::kLsd, 1, 0.15},
                                           Case{LineDetectorOptions::Method::kEdLines, 0, 0.5},
                                           Case{LineDetectorOptions::Method::kEdLines, 1, 1.0},
                                           Case{LineDetectorOptions::Method::kFld, 0, 0.5},
                                           Case{LineDetectorOptions::Method::kFld, 1, 1.0}));

TEST(LineDetector, ConvertsFloatFramesAndRejectsBadInput) {
  cv::Mat f(4, 4, CV_32F, cv::Scalar(254.6f));
  f.at<float>(0, 0) = 300.f;
  f.at<float>(0, 1) = -3.f;
  const cv::Mat g = ToGray8(f);
  EXPECT_EQ(g.type(), CV_8U);
  EXPECT_EQ(g.at<uint8_t>(1, 1), 255);
  EXPECT_EQ(g.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(g.at<uint8_t>(0, 1), 0);
  EXPECT_THROW(ToGray8(cv::Mat(4, 4, CV_32FC3)), std::invalid_argument);
  EXPECT_THROW(ToGray8(cv::Mat()), std::invalid_argument);

  LineDetectorOptions options;
  options.first_octave = 1;
  options.num_octaves = 2;
  LineDetector detector(options);
  EXPECT_THROW(detector.Detect(BuildOctaves(g, 2)), std::invalid_argument);  // needs 3 octaves
  options.num_octaves = 0;
  EXPECT_THROW(LineDetector{options}, std::invalid_argument);
}

// EdgeDrawing's a-contrario validation (`edlines_nfa_validation`) rejects lines fitted to noise:
// on blurred white noise it keeps under half of the lines found without it, while the
// rectangle's four sides are found either way.
TEST(LineDetector, NfaValidationRejectsLinesFittedToNoise) {
  const cv::Mat noise = test::RandomTexture(cv::Size(640, 480), 7, 1.5);
  LineDetectorOptions options;
  options.num_octaves = 1;
  options.edlines_nfa_validation = false;
  LineDetector without_nfa(options);
  options.edlines_nfa_validation = true;
  LineDetector with_nfa(options);
  const size_t n_without = without_nfa.Detect(BuildOctaves(noise, 1)).size();
  const size_t n_with = with_nfa.Detect(BuildOctaves(noise, 1)).size();
  std::cout << "lines on noise: " << n_without << " without NFA, " << n_with << " with\n";
  EXPECT_GT(n_without, 20u);
  EXPECT_LT(2 * n_with, n_without);
  const cv::Mat rectangle = RectangleImage();
  EXPECT_EQ(without_nfa.Detect(BuildOctaves(rectangle, 1)).size(), 4u);
  EXPECT_EQ(with_nfa.Detect(BuildOctaves(rectangle, 1)).size(), 4u);
}

}  // namespace
}  // namespace pldvo
