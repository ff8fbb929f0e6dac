// LineFrontend orchestration, LBD KeyLines, the matcher on a translated image, and options.
#include "frontend/line_frontend.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>

#include "tests/random_texture.h"

namespace pldvo {
namespace {

// A 640x480 image with a few rectangles of different gray levels plus mild noise (seeded).
cv::Mat BlocksImage(const Eigen::Vector2d& offset) {
  cv::Mat image(480, 640, CV_32F, cv::Scalar(90.f));
  const std::vector<std::pair<cv::Rect2d, float>> blocks = {{{60, 50, 200, 140}, 180.f},
                                                            {{330, 70, 230, 100}, 40.f},
                                                            {{120, 260, 120, 170}, 150.f},
                                                            {{300, 240, 260, 60}, 200.f},
                                                            {{380, 340, 90, 100}, 20.f}};
  // Subpixel-exact areas: supersample 4x.
  cv::Mat big(480 * 4, 640 * 4, CV_32F, cv::Scalar(90.f));
  for (const auto& [r, value] : blocks) {
    const cv::Rect rb(static_cast<int>(std::lround((r.x + offset.x() + 0.5) * 4)),
                      static_cast<int>(std::lround((r.y + offset.y() + 0.5) * 4)),
                      static_cast<int>(r.width * 4), static_cast<int>(r.height * 4));
    big(rb & cv::Rect(0, 0, big.cols, big.rows)).setTo(value);
  }
  cv::resize(big, image, image.size(), 0, 0, cv::INTER_AREA);
  cv::Mat noise(image.size(), CV_32F);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  return image + noise;
}

TEST(LineFrontend, ProcessFillsSegmentsDescriptorsAndTiming) {
  LineFrontendOptions options;
  options.descriptor.on_demand = false;
  LineFrontend frontend{options};
  const LineFrame frame = frontend.Process(BlocksImage(Eigen::Vector2d::Zero()));
  EXPECT_TRUE(frame.FullyDescribed());
  EXPECT_TRUE(frame.gray.empty());
  // 5 rectangles x 4 sides, at most 1 segment per side after merging (the sides are straight
  // and long, so a second piece would be a merger failure).
  EXPECT_EQ(frame.segments.size(), 20u);
  EXPECT_EQ(frame.descriptors.rows, static_cast<int>(frame.segments.size()));
  EXPECT_EQ(frame.descriptors.cols, 32);
  EXPECT_EQ(frame.image_size, cv::Size(640, 480));
  EXPECT_GE(frame.timing.num_detected, frame.timing.num_lines);
  EXPECT_EQ(frame.timing.num_lines, static_cast<int>(frame.segments.size()));
  EXPECT_GT(frame.timing.detection_ms, 0.0);
  EXPECT_GT(frame.timing.description_ms, 0.0);
  for (const LineSegment& s : frame.segments) {
    EXPECT_GE(s.length, frontend.options().merger.min_length_px);
    // Sigma_l: symmetric PSD of rank 2 with (a, b) normalised, so l^T... its null direction
    // keeps a^2 + b^2 = 1: (a, b, 0) Sigma_l (a, b, 0)^T = 0 to first order.
    EXPECT_LT((s.line_cov - s.line_cov.transpose()).norm(), 1e-12);
    const Eigen::Vector3d ab(s.line.x(), s.line.y(), 0.0);
    EXPECT_NEAR(ab.dot(s.line_cov * ab), 0.0, 1e-12);
    EXPECT_GT(s.line_cov.trace(), 0.0);
  }
}

TEST(LbdDescriber, KeyLinesFollowBinaryDescriptorConventions) {
  LineDescriptorOptions options;
  options.min_octave = 0;
  const LbdDescriber describer(options);
  const std::vector<LineSegment> segments = {MakeLineSegment({10, 20}, {110, 20}, 0, 0.5),
                                             MakeLineSegment({40, 300}, {40, 100}, 1, 1.0)};
  const auto keylines = describer.MakeKeyLines(segments, {640, 480});
  ASSERT_EQ(keylines.size(), 2u);
  EXPECT_EQ(keylines[1].class_id, 1);
  EXPECT_EQ(keylines[1].octave, 1);
  EXPECT_FLOAT_EQ(keylines[1].sPointInOctaveX, 20.f);
  EXPECT_FLOAT_EQ(keylines[1].ePointInOctaveY, 50.f);
  EXPECT_FLOAT_EQ(keylines[1].lineLength, 100.f);
  EXPECT_EQ(keylines[1].numOfPixels, 100);
  EXPECT_NEAR(keylines[1].angle, -M_PI / 2, 1e-6);
  EXPECT_EQ(keylines[0].octave, 0);
  EXPECT_FLOAT_EQ(keylines[0].endPointX, 110.f);
}

// max_support_px = C describes a segment longer than C by its central C octave pixels: the
// descriptor equals that of the central piece of length C described whole, and differs from the
// whole segment's on a textured image.
TEST(LbdDescriber, MaxSupportDescribesTheCentralPartOfTheSegment) {
  const cv::Mat texture = test::RandomTexture(cv::Size(640, 480), 3, 2.0);
  LineDescriptorOptions capped;
  capped.min_octave = 0;
  capped.max_support_px = 40;
  LineDescriptorOptions whole = capped;
  whole.max_support_px = 0;
  LbdDescriber capped_describer(capped);
  LbdDescriber whole_describer(whole);
  const std::vector<LineSegment> segment = {
      MakeLineSegment({100, 200}, {300, 240}, 0, 0.5)};  // length 204, midpoint (200, 220)
  const Eigen::Vector2d mid(200, 220);
  const Eigen::Vector2d half = 20.0 * (segment[0].end - segment[0].start).normalized();
  const std::vector<LineSegment> central = {MakeLineSegment(mid - half, mid + half, 0, 0.5)};
  EXPECT_EQ(capped_describer.MakeKeyLines(segment, texture.size())[0].numOfPixels, 40);
  const cv::Mat d_capped = capped_describer.Describe(texture, segment);
  const cv::Mat d_central = whole_describer.Describe(texture, central);
  const cv::Mat d_whole = whole_describer.Describe(texture, segment);
  std::cout << "capped vs whole segment: Hamming "
            << HammingDistance32(d_capped.ptr(0), d_whole.ptr(0)) << "\n";
  EXPECT_EQ(HammingDistance32(d_capped.ptr(0), d_central.ptr(0)), 0);
  EXPECT_GT(HammingDistance32(d_capped.ptr(0), d_whole.ptr(0)), 20);
  // A segment shorter than the cap is described whole.
  EXPECT_EQ(HammingDistance32(capped_describer.Describe(texture, central).ptr(0), d_central.ptr(0)),
            0);
  capped.max_support_px = 1;
  EXPECT_THROW(LbdDescriber{capped}, std::invalid_argument);
}

// The image translated by (14.5, -9.25) px: every segment must match its translated self,
// with and without a prediction.
TEST(LineMatcher, MatchesTranslatedImage) {
  LineFrontend frontend{LineFrontendOptions()};
  const Eigen::Vector2d shift(14.5, -9.25);
  LineFrame ref = frontend.Process(BlocksImage(Eigen::Vector2d::Zero()));
  LineFrame cur = frontend.Process(BlocksImage(shift));
  Eigen::Matrix3d translation = Eigen::Matrix3d::Identity();
  translation.topRightCorner<2, 1>() = shift;
  for (const SegmentPredictor& predictor :
       {SegmentPredictor(), PredictorFromHomography(translation)}) {
    const std::vector<LineMatch> matches = frontend.Match(&ref, &cur, predictor);
    // Segments touching the image border after the shift may change; all others must match.
    EXPECT_GE(matches.size(), 18u);
    std::set<int> used;
    for (const LineMatch& m : matches) {
      const LineSegment& r = ref.segments[m.ref_index];
      const LineSegment& c = cur.segments[m.cur_index];
      EXPECT_TRUE(used.insert(m.cur_index).second) << "current segment matched twice";
      // Same edge: the shifted reference midpoint lies on the current line (0.5 px: EDLines
      // fits integer edge pixels) and the directions agree (polarity included).
      EXPECT_LT(std::abs(c.SignedDistance(r.midpoint() + shift)), 0.5);
      EXPECT_LT(AngleDifference(r.angle, c.angle), 1.0 * M_PI / 180);
      EXPECT_LE(m.distance, frontend.options().matcher.max_hamming);
    }
  }
}

TEST(LbdDescriber, RowsOfASubsetEqualThoseOfTheWholeList) {
  LineFrontendOptions options;
  options.descriptor.on_demand = false;
  LineFrontend frontend{options};
  const cv::Mat image = BlocksImage(Eigen::Vector2d::Zero());
  const LineFrame frame = frontend.Process(image);
  ASSERT_GE(frame.segments.size(), 10u);
  std::vector<int> rows;
  for (int i = 1; i < static_cast<int>(frame.segments.size()); i += 3) rows.push_back(i);
  LbdDescriber describer{options.descriptor};
  cv::Mat subset = cv::Mat::zeros(frame.descriptors.size(), CV_8U);
  describer.DescribeRows(ToGray8(image), frame.segments, rows, &subset);
  for (int i = 0; i < subset.rows; ++i) {
    const bool listed = std::find(rows.begin(), rows.end(), i) != rows.end();
    EXPECT_EQ(cv::countNonZero(subset.row(i) != frame.descriptors.row(i)) == 0, listed) << i;
  }
}

// Descriptions on demand give the matches of describing everything, and describe only the
// frame's segments that the gates pass: here the predictor drops every odd keyframe segment, so
// the frame's segments on those edges stay undescribed; the keyframe is described whole.
TEST(LineFrontend, OnDemandDescriptionMatchesAsDescribingEverything) {
  const Eigen::Vector2d shift(14.5, -9.25);
  LineFrontendOptions eager_options;
  eager_options.descriptor.on_demand = false;
  LineFrontend eager{eager_options};
  LineFrontend lazy{LineFrontendOptions()};
  ASSERT_TRUE(lazy.options().descriptor.on_demand);
  Eigen::Matrix3d translation = Eigen::Matrix3d::Identity();
  translation.topRightCorner<2, 1>() = shift;
  const SegmentPredictor by_translation = PredictorFromHomography(translation);
  LineFrame ref = eager.Process(BlocksImage(Eigen::Vector2d::Zero()));
  const LineFrame cur = eager.Process(BlocksImage(shift));
  std::map<const LineSegment*, int> index_of;
  for (size_t i = 0; i < ref.segments.size(); ++i) index_of[&ref.segments[i]] = i;
  const SegmentPredictor even_only = [&](const LineSegment& s, Eigen::Vector2d* a,
                                         Eigen::Vector2d* b) {
    const auto it = index_of.find(&s);
    return it != index_of.end() && it->second % 2 == 0 && by_translation(s, a, b);
  };
  LineFrame eager_cur = cur;
  const std::vector<LineMatch> expected = eager.Match(&ref, &eager_cur, even_only);

  LineFrame lazy_ref = lazy.Process(BlocksImage(Eigen::Vector2d::Zero()));
  LineFrame lazy_cur = lazy.Process(BlocksImage(shift));
  EXPECT_FALSE(lazy_ref.gray.empty());
  EXPECT_EQ(std::count(lazy_cur.described.begin(), lazy_cur.described.end(), 1), 0);
  index_of.clear();
  for (size_t i = 0; i < lazy_ref.segments.size(); ++i) index_of[&lazy_ref.segments[i]] = i;
  LineFrontendTiming timing;
  const std::vector<LineMatch> matches = lazy.Match(&lazy_ref, &lazy_cur, even_only, &timing);
  ASSERT_GE(expected.size(), 8u);
  ASSERT_EQ(matches.size(), expected.size());
  for (size_t k = 0; k < matches.size(); ++k) {
    EXPECT_EQ(matches[k].ref_index, expected[k].ref_index);
    EXPECT_EQ(matches[k].cur_index, expected[k].cur_index);
    EXPECT_EQ(matches[k].distance, expected[k].distance);
  }
  EXPECT_GT(timing.description_ms, 0.0);
  EXPECT_TRUE(lazy_ref.FullyDescribed());
  EXPECT_TRUE(lazy_ref.gray.empty());
  EXPECT_EQ(cv::countNonZero(lazy_ref.descriptors != ref.descriptors), 0);
  const int cur_described = std::count(lazy_cur.described.begin(), lazy_cur.described.end(), 1);
  EXPECT_GE(cur_described, static_cast<int>(matches.size()));
  EXPECT_LE(cur_described, static_cast<int>(lazy_cur.segments.size() + 3) / 2);
  // A hand-made frame without the flags is refused, not read out of bounds.
  LineFrame hand_made = cur;
  hand_made.described.clear();
  EXPECT_THROW(lazy.Match(&lazy_ref, &hand_made), std::invalid_argument);
  // Completing the description gives the eager rows and releases the image.
  std::vector<int> all(lazy_cur.segments.size());
  std::iota(all.begin(), all.end(), 0);
  lazy.Describe(all, &lazy_cur);
  EXPECT_TRUE(lazy_cur.FullyDescribed());
  EXPECT_TRUE(lazy_cur.gray.empty());
  EXPECT_EQ(cv::countNonZero(lazy_cur.descriptors != cur.descriptors), 0);
}

TEST(LineMatcher, GatingRejectsFarAndOppositeCandidates) {
  // Identical descriptors everywhere: only the geometry decides.
  const std::vector<LineSegment> ref = {MakeLineSegment({100, 100}, {200, 100}, 0, 0.5)};
  const std::vector<LineSegment> cur = {
      MakeLineSegment({100, 300}, {200, 300}, 0, 0.5),   // 200 px away
      MakeLineSegment({200, 101}, {100, 101}, 0, 0.5)};  // opposite polarity
  const cv::Mat ref_desc(1, 32, CV_8U, cv::Scalar(7));
  const cv::Mat cur_desc(2, 32, CV_8U, cv::Scalar(7));
  const LineMatcher matcher{LineMatcherOptions()};
  EXPECT_TRUE(matcher.Match(ref, ref_desc, cur, cur_desc).empty());
  // A prediction moving the reference onto the far candidate makes it match.
  Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
  shift(1, 2) = 200.0;
  const auto matches = matcher.Match(ref, ref_desc, cur, cur_desc, PredictorFromHomography(shift));
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].cur_index, 0);
  EXPECT_EQ(matches[0].distance, 0);
  EXPECT_THROW(matcher.Match(ref, cur_desc, cur, cur_desc), std::invalid_argument);
}

TEST(LineMatcher, RatioTestRejectsAmbiguousMatches) {
  const std::vector<LineSegment> ref = {MakeLineSegment({100, 100}, {200, 100}, 0, 0.5)};
  const std::vector<LineSegment> cur = {MakeLineSegment({100, 102}, {200, 102}, 0, 0.5),
                                        MakeLineSegment({100, 106}, {200, 106}, 0, 0.5)};
  cv::Mat ref_desc(1, 32, CV_8U, cv::Scalar(0));
  cv::Mat cur_desc(2, 32, CV_8U, cv::Scalar(0));
  cur_desc.at<uint8_t>(0, 0) = 0x0f;  // distance 4
  cur_desc.at<uint8_t>(1, 0) = 0x1f;  // distance 5: 4 >= 0.8 * 5, ambiguous
  const LineMatcher matcher{LineMatcherOptions()};
  EXPECT_TRUE(matcher.Match(ref, ref_desc, cur, cur_desc).empty());
  cur_desc.at<uint8_t>(1, 1) = 0xff;  // distance 13: 4 < 0.8 * 13
  const auto matches = matcher.Match(ref, ref_desc, cur, cur_desc);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].cur_index, 0);
  EXPECT_EQ(matches[0].distance, 4);
}

// Every field is visited with a non-empty doc, names are unique, and defaults pass Check.
struct CollectingVisitor {
  std::string prefix;
  std::map<std::string, std::string>* docs;
  template <class T>
  void Field(const std::string& name, T*, const std::string& doc) {
    EXPECT_TRUE(docs->emplace(prefix + name, doc).second) << name;
    EXPECT_FALSE(doc.empty()) << name;
  }
  template <class Enum>
  void Choice(const std::string& name, Enum*, const ChoiceNames<Enum>& names,
              const std::string& doc) {
    EXPECT_FALSE(names.empty());
    Field(name, static_cast<Enum*>(nullptr), doc);
  }
  template <class Sub>
  void Section(const std::string& name, Sub* sub, const std::string&) {
    CollectingVisitor inner{prefix + name + ".", docs};
    sub->VisitFields(inner);
  }
};

TEST(LineFrontendOptions, FieldsDocumentedAndChecked) {
  LineFrontendOptions options;
  std::map<std::string, std::string> docs;
  CollectingVisitor visitor{"", &docs};
  options.VisitFields(visitor);
  EXPECT_GT(docs.size(), 30u);
  EXPECT_EQ(docs.count("detector.method"), 1u);
  EXPECT_EQ(docs.count("matcher.ratio"), 1u);
  EXPECT_EQ(options.Check(), "");
  options.matcher.ratio = 1.5;
  EXPECT_NE(options.Check().find("matcher.ratio"), std::string::npos);
  EXPECT_THROW(LineFrontend{options}, std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
