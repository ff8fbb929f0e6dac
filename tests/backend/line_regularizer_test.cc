// 3D line regularisation (backend/mapping/line_regularizer.h): known 3D lines, noisy inverse depths
// with outliers -> the RANSAC + weighted least-squares line is recovered, outliers are rejected and
// the pixels' depth error drops.
#include "backend/mapping/line_regularizer.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "core/random_draws.h"
#include "core/statistics.h"
#include "frontend/line_segment.h"

namespace pldvo {
namespace {

PinholeCamera TestCamera() { return PinholeCamera{320, 240, 260.0, 260.0, 159.5, 119.5}; }

struct EdgeCase {
  TracedLine line;
  std::vector<double> gt_idepth;
  std::vector<bool> outlier;
};

// Pixels along the projection of a-b, the GT inverse depth of the 3D line at each pixel (closest
// point to the ray), noisy values with relative sigma `rel_sigma`, a fraction of outliers.
EdgeCase MakeEdge(const PinholeCamera& camera, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                  double rel_sigma, double outlier_fraction, std::mt19937* rng,
                  SemiDenseDepthMap* map) {
  EdgeCase edge;
  const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
  edge.line.id = 0;
  edge.line.segment = MakeLineSegment(pa, pb, 0, 0.5);
  std::set<std::pair<int, int>> seen;
  const int steps = static_cast<int>(2.0 * (pb - pa).norm());
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector2d p = pa + (pb - pa) * k / steps;
    const Eigen::Vector2i pixel(static_cast<int>(std::lround(p.x())),
                                static_cast<int>(std::lround(p.y())));
    if (!seen.insert({pixel.x(), pixel.y()}).second) continue;
    const Eigen::Vector3d r = camera.Unproject(pixel.cast<double>());
    const Eigen::Vector3d d = b - a;
    Eigen::Matrix2d m;
    m << r.dot(r), -r.dot(d), r.dot(d), -d.dot(d);
    const Eigen::Vector2d ts = m.inverse() * Eigen::Vector2d(r.dot(a), d.dot(a));
    const double gt = 1.0 / (a + ts.y() * d).z();
    const bool outlier = uniform(*rng) < outlier_fraction;
    const double sigma = rel_sigma * gt;
    const double value = outlier ? gt * (1.3 + 0.5 * uniform(*rng)) : gt + sigma * noise(*rng);
    map->Set(map->Index(pixel.x(), pixel.y()), value, sigma * sigma, 20);
    edge.line.pixels.push_back(pixel);
    edge.gt_idepth.push_back(gt);
    edge.outlier.push_back(outlier);
  }
  return edge;
}

double MedianRelError(const EdgeCase& edge, const SemiDenseDepthMap& map) {
  std::vector<double> errors;
  for (size_t i = 0; i < edge.line.pixels.size(); ++i) {
    if (edge.outlier[i]) continue;
    const int index = map.Index(edge.line.pixels[i].x(), edge.line.pixels[i].y());
    errors.push_back(std::abs(map.idepth(index) - edge.gt_idepth[i]) / edge.gt_idepth[i]);
  }
  return Median(errors);
}

TEST(LineRegularizerTest, RecoversKnownLinesAndRejectsOutliers) {
  const PinholeCamera camera = TestCamera();
  MappingOptions options;
  const LineRegularizer regularizer(options);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int tested = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d ra = DrawVector3(u, rng);
    const Eigen::Vector3d a(ra.x(), 0.6 * ra.y(), 2.5 + ra.z());
    const Eigen::Vector3d rb = DrawVector3(u, rng);
    const Eigen::Vector3d b(rb.x(), 0.6 * rb.y(), 2.5 + rb.z());
    const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
    if ((pb - pa).norm() < 60.0 || !camera.IsInside(pa, 2) || !camera.IsInside(pb, 2)) continue;
    ++tested;
    SemiDenseDepthMap map(camera.width, camera.height);
    // 5% relative noise, 20% outliers 30-80% too near.
    const EdgeCase edge = MakeEdge(camera, a, b, 0.05, 0.2, &rng, &map);
    const LineFit fit =
        regularizer.FitEdge(camera, edge.line.segment.line, edge.line.pixels, map, &rng);
    ASSERT_TRUE(fit.ok) << "trial " << trial;
    // Outliers sit >= 6 sigma off the line (30% at 5% sigma), so every one must be rejected;
    // inliers are kept unless beyond the 99% gate (1% expected; 5% allowed).
    int kept_inliers = 0, num_inliers = 0;
    for (size_t i = 0; i < edge.outlier.size(); ++i) {
      if (edge.outlier[i]) {
        EXPECT_FALSE(fit.inlier[i]) << "trial " << trial << " pixel " << i;
      } else {
        ++num_inliers;
        kept_inliers += fit.inlier[i];
      }
    }
    EXPECT_GE(kept_inliers, 0.95 * num_inliers);
    // Recovered 3D line: the GT endpoints' distance to it, relative to depth. N >= 60 pixels of 5%
    // noise give ~0.05 / sqrt(N / 2) < 1% at the ends; 2% tolerance.
    const Eigen::Vector3d point = fit.PointInRef(), direction = fit.DirectionInRef();
    for (const Eigen::Vector3d& p : {a, b}) {
      const Eigen::Vector3d offset = p - point;
      EXPECT_LT((offset - offset.dot(direction) * direction).norm() / p.z(), 0.02)
          << "trial " << trial;
    }
    // Regularise: inlier pixels' median error falls well below the 5% input noise (median
    // |N(0, 5%)| = 3.4%); 1.5% allowed.
    EdgeTrace trace;
    trace.lines.push_back(edge.line);
    const double before = MedianRelError(edge, map);
    const LineRegularizationStats stats = regularizer.Regularize(camera, trace, &map);
    EXPECT_EQ(stats.edges_fitted, 1);
    const double after = MedianRelError(edge, map);
    EXPECT_LT(after, 0.015) << "before " << before;
    EXPECT_LT(after, before);
  }
  EXPECT_GE(tested, 8);
}

TEST(LineRegularizerTest, TooFewPixelsIsRejected) {
  const PinholeCamera camera = TestCamera();
  MappingOptions options;
  const LineRegularizer regularizer(options);
  SemiDenseDepthMap map(camera.width, camera.height);
  std::mt19937 rng(1);
  TracedLine line;
  line.segment = MakeLineSegment(Eigen::Vector2d(10, 10), Eigen::Vector2d(20, 10), 0, 0.5);
  for (int x = 10; x < 15; ++x) {
    line.pixels.emplace_back(x, 10);
    map.Set(map.Index(x, 10), 0.5, 0.01, 20);
  }
  EXPECT_FALSE(regularizer.FitEdge(camera, line.segment.line, line.pixels, map, &rng).ok);
}

}  // namespace
}  // namespace pldvo
