// EdgeTracer: every traced pixel lies within half_width + 0.5 px of its segment, the traced
// band covers the segment, and the id map and the per-line pixel lists agree exactly, also
// where lines cross.
#include "frontend/edge_tracer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

namespace pldvo {
namespace {

double DistanceToSegment(const LineSegment& s, const Eigen::Vector2d& p) {
  const double t = std::clamp(s.Project(p), 0.0, s.length);
  return (s.start + t * s.direction() - p).norm();
}

TEST(EdgeTracer, PixelsNearSegmentsAndMapConsistent) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(-20.0, 660.0), y(-20.0, 500.0);
  std::vector<LineSegment> segments;
  while (segments.size() < 60) {
    const double ay = y(rng), ax = x(rng), by = y(rng), bx = x(rng);  // core/random_draws.h
    const Eigen::Vector2d a(ax, ay), b(bx, by);
    if ((a - b).norm() > 5.0) segments.push_back(MakeLineSegment(a, b, 0, 0.5));
  }
  std::vector<int> ids;
  for (int i = 0; i < 60; i += 2) ids.push_back(i);  // trace every other segment
  const cv::Size size(640, 480);
  const EdgeTracer tracer{EdgeTracerOptions()};
  const EdgeTrace trace = tracer.Trace(segments, ids, size);
  ASSERT_EQ(trace.id_map.type(), CV_32S);
  ASSERT_EQ(trace.lines.size(), ids.size());

  std::set<std::pair<int, int>> listed;
  int total = 0;
  for (const TracedLine& line : trace.lines) {
    EXPECT_EQ(line.id % 2, 0);
    EXPECT_EQ(line.segment.start, segments[line.id].start);
    EXPECT_EQ(line.segment.line_cov, segments[line.id].line_cov);
    for (const Eigen::Vector2i& p : line.pixels) {
      // 1 px widening + 0.5 px rounding along the minor axis bound the distance (header).
      EXPECT_LE(DistanceToSegment(line.segment, p.cast<double>()), 1.5 + 1e-9);
      EXPECT_EQ(trace.id_map.at<int>(p.y(), p.x()), line.id);
      EXPECT_TRUE(listed.insert({p.x(), p.y()}).second) << "pixel listed twice";
      ++total;
    }
  }
  // Every labelled pixel appears in exactly one list.
  EXPECT_EQ(cv::countNonZero(trace.id_map >= 0), total);
  EXPECT_GT(total, 1000);
}

TEST(EdgeTracer, BandCoversHorizontalAndDiagonalLines) {
  const std::vector<LineSegment> segments = {MakeLineSegment({10.2, 20.4}, {60.2, 20.4}, 0, 0.5),
                                             MakeLineSegment({100, 100}, {150, 150}, 0, 0.5)};
  const EdgeTrace trace = EdgeTracer(EdgeTracerOptions()).Trace(segments, {0, 1}, {200, 200});
  // Horizontal: columns 11..60, rows 19..21 (centre row round(20.4) = 20 widened by 1).
  EXPECT_EQ(trace.lines[0].pixels.size(), 50u * 3u);
  for (int x = 11; x <= 60; ++x) {
    for (int y = 19; y <= 21; ++y) EXPECT_EQ(trace.id_map.at<int>(y, x), 0);
  }
  // Diagonal: 51 columns x 3 pixels.
  EXPECT_EQ(trace.lines[1].pixels.size(), 51u * 3u);
}

TEST(EdgeTracer, RejectsBadIds) {
  const std::vector<LineSegment> segments = {MakeLineSegment({0, 0}, {10, 10}, 0, 0.5)};
  const EdgeTracer tracer{EdgeTracerOptions()};
  EXPECT_THROW(tracer.Trace(segments, {1}, {20, 20}), std::invalid_argument);
  EXPECT_THROW(tracer.Trace(segments, {0, 0}, {20, 20}), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
