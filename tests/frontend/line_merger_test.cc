// LineMerger on hand-made segments: broken collinear pieces and cross-octave duplicates merge
// into one segment spanning their extremes; parallel offsets, angled pieces, far gaps and
// opposite polarities stay apart; short results are dropped.
#include "frontend/line_merger.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/random_draws.h"

namespace pldvo {
namespace {

LineSegment Seg(double x0, double y0, double x1, double y1, int octave = 0) {
  return MakeLineSegment({x0, y0}, {x1, y1}, octave, 0.5);
}

TEST(LineMerger, MergesBrokenCollinearPieces) {
  LineMergerOptions options;
  const LineMerger merger(options, 0.5);
  // Three pieces of the line y = 100 + 0.2 x with gaps of 5 px and sub-pixel noise, and a
  // coarse-octave duplicate overlapping the first two.
  auto y = [](double x) { return 100.0 + 0.2 * x; };
  const std::vector<LineSegment> pieces = {
      Seg(10, y(10) + 0.3, 90, y(90) - 0.2), Seg(95, y(95), 180, y(180) + 0.3),
      Seg(185, y(185) - 0.3, 300, y(300)), Seg(40, y(40) + 0.5, 150, y(150) - 0.4, 1)};
  const std::vector<LineSegment> merged = merger.Merge(pieces);
  ASSERT_EQ(merged.size(), 1u);
  const LineSegment& s = merged[0];
  // The merged segment spans the extreme projections: x from 10 to 300 (to within the
  // 0.5 px noise), stays on the line and keeps the direction and finest octave.
  EXPECT_NEAR(s.start.x(), 10.0, 0.5);
  EXPECT_NEAR(s.end.x(), 300.0, 0.5);
  EXPECT_NEAR(s.start.y(), y(10), 0.5);
  EXPECT_NEAR(s.end.y(), y(300), 0.5);
  EXPECT_EQ(s.octave, 0);
  EXPECT_NEAR(s.line.head<2>().norm(), 1.0, 1e-12);
}

TEST(LineMerger, KeepsDistinctSegmentsApart) {
  LineMergerOptions options;
  const LineMerger merger(options, 0.5);
  const std::vector<LineSegment> segments = {
      Seg(10, 100, 200, 100),  // reference
      Seg(10, 104, 200, 104),  // parallel, 4 px away (> max_line_distance_px)
      Seg(210, 100, 400, 100 + 190 * std::tan(10 * M_PI / 180)),  // 10 deg off
      Seg(230, 100, 330, 100),     // collinear but 30 px gap (> max_gap_px)
      Seg(200, 100.5, 20, 100.5),  // same place, opposite polarity
  };
  const std::vector<LineSegment> merged = merger.Merge(segments);
  EXPECT_EQ(merged.size(), segments.size());
}

TEST(LineMerger, DropsShortSegmentsAndCanBeDisabled) {
  LineMergerOptions options;
  options.min_length_px = 20.0;
  const std::vector<LineSegment> segments = {Seg(0, 0, 10, 0), Seg(12, 0, 25, 0),
                                             Seg(100, 50, 110, 50)};
  // Enabled: the first two merge into one 25 px segment; the third (10 px) is dropped.
  const std::vector<LineSegment> merged = LineMerger(options, 0.5).Merge(segments);
  ASSERT_EQ(merged.size(), 1u);
  EXPECT_NEAR(merged[0].length, 25.0, 1e-9);
  // Disabled: only the length filter applies, and all three are shorter than 20 px.
  options.enabled = false;
  EXPECT_TRUE(LineMerger(options, 0.5).Merge(segments).empty());
}

TEST(LineMerger, KeepsTheLongestMaxSegments) {
  // Five parallel, separate segments of lengths 30..70 px: max_segments = 2 keeps the 70 and
  // 60 px ones, longest first, with merging enabled or not; 0 keeps all five.
  std::vector<LineSegment> segments;
  for (int i = 0; i < 5; ++i) segments.push_back(Seg(0, 40.0 * i, 30.0 + 10.0 * i, 40.0 * i));
  LineMergerOptions options;
  options.max_segments = 2;
  for (const bool enabled : {true, false}) {
    options.enabled = enabled;
    const std::vector<LineSegment> kept = LineMerger(options, 0.5).Merge(segments);
    ASSERT_EQ(kept.size(), 2u);
    EXPECT_NEAR(kept[0].length, 70.0, 1e-9);
    EXPECT_NEAR(kept[1].length, 60.0, 1e-9);
  }
  options.max_segments = 0;
  EXPECT_EQ(LineMerger(options, 0.5).Merge(segments).size(), 5u);
}

TEST(LineMerger, ManyRandomFragmentsOfFewLines) {
  // 12 random lines, each cut into 2..5 pieces with gaps <= 6 px and 0.3 px noise, shuffled;
  // merging must restore exactly 12 segments.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<LineSegment> pieces;
  for (int line = 0; line < 12; ++line) {
    const Eigen::Vector2d u = DrawVector2(uniform, rng);
    const Eigen::Vector2d origin(50 + 540 * u.x(), 50 + 380 * u.y());
    const double angle = 2 * M_PI * uniform(rng);
    const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d n(-d.y(), d.x());
    double t = 0.0;
    const int num_pieces = 2 + line % 4;
    for (int k = 0; k < num_pieces; ++k) {
      const double length = 30 + 40 * uniform(rng);
      const Eigen::Vector2d a = origin + t * d + 0.3 * (2 * uniform(rng) - 1) * n;
      const Eigen::Vector2d b = origin + (t + length) * d + 0.3 * (2 * uniform(rng) - 1) * n;
      pieces.push_back(MakeLineSegment(a, b, 0, 0.5));
      t += length + 6.0 * uniform(rng);
    }
  }
  std::shuffle(pieces.begin(), pieces.end(), rng);
  const std::vector<LineSegment> merged = LineMerger(LineMergerOptions(), 0.5).Merge(pieces);
  // Random lines may cross; crossing lines differ in angle by more than 3 deg unless nearly
  // parallel, so the count is exact for this seed.
  EXPECT_EQ(merged.size(), 12u);
}

}  // namespace
}  // namespace pldvo
