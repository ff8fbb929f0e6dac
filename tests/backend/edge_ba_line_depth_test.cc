// Edge BA lines -> keyframe inverse depths (backend/edge_ba/edge_ba_line_depth.h,
// DepthMapper::FuseLineDepths): the ray/line intersection, its first-order variance against Monte
// Carlo sampling of the line's tangent perturbation, the covariance change of frame, and the
// fusion into a depth map with wrong edge depths.
#include "backend/edge_ba/edge_ba_line_depth.h"

#include <ceres/line_manifold.h>
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "backend/edge_ba/edge_ba_solver.h"
#include "backend/mapping/depth_mapper.h"
#include "experiments/evaluation/edge_ba_simulation.h"

namespace pldvo {
namespace {

PinholeCamera TestCamera() { return PinholeCamera{320, 240, 250.0, 250.0, 160.0, 120.0}; }

// A positive definite tangent covariance with correlations: sigmas of 1-2 cm (origin) and
// 0.3-0.6 deg (direction) for a line ~3 m away, small enough for the first order to hold.
Eigen::Matrix4d TestCovariance() {
  Eigen::Matrix4d a;
  a << 0.010, 0.002, 0.000, 0.001,  //
      0.000, 0.015, 0.003, 0.000,   //
      0.001, 0.000, 0.006, 0.002,   //
      0.000, 0.001, 0.000, 0.009;
  return a * a.transpose();
}

// Sample variance of f(Plus(line, delta)), delta ~ N(0, cov), over n seeded samples; false when
// any sample fails.
template <class F>
double MonteCarloVariance(const KeyframeLine& line, const Eigen::Matrix4d& cov, int n, F f) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const Eigen::Matrix4d l = cov.llt().matrixL();
  const double x[6] = {line.point.x(),     line.point.y(),     line.point.z(),
                       line.direction.x(), line.direction.y(), line.direction.z()};
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector4d z;
    for (int k = 0; k < 4; ++k) z[k] = normal(rng);
    const Eigen::Vector4d delta = l * z;
    double plus[6];
    ceres::LineManifold<3>().Plus(x, delta.data(), plus);
    const double value =
        f(Eigen::Vector3d(plus[0], plus[1], plus[2]), Eigen::Vector3d(plus[3], plus[4], plus[5]));
    sum += value;
    sum2 += value * value;
  }
  const double mean = sum / n;
  return (sum2 - n * mean * mean) / (n - 1);
}

TEST(EdgeBALineDepthTest, IntersectsRayAndLine) {
  const PinholeCamera camera = TestCamera();
  // A line through the points at depth 2 and 4 m seen at pixels (100, 80) and (220, 150).
  const Eigen::Vector3d p0 = 2.0 * camera.Unproject(Eigen::Vector2d(100, 80));
  const Eigen::Vector3d p1 = 4.0 * camera.Unproject(Eigen::Vector2d(220, 150));
  double idepth = 0.0;
  ASSERT_TRUE(RayLineInverseDepth(camera, Eigen::Vector2d(100, 80), p1, p1 - p0, 1e-3, &idepth));
  EXPECT_NEAR(idepth, 0.5, 1e-12);
  // The midpoint projects to some pixel; its inverse depth is 1 / 3.
  const Eigen::Vector3d mid = 0.5 * (p0 + p1);
  const Eigen::Vector2d mid_px = camera.Project(mid);
  ASSERT_TRUE(RayLineInverseDepth(camera, mid_px, p0, p1 - p0, 1e-3, &idepth));
  EXPECT_NEAR(idepth, 1.0 / 3.0, 1e-12);
  // 5 px off the line's image misses it by ~5/250 rad > 2/250: skipped.
  const Eigen::Vector2d normal_px = Eigen::Vector2d(-(150 - 80), 220 - 100).normalized();
  EXPECT_FALSE(
      RayLineInverseDepth(camera, mid_px + 5.0 * normal_px, p0, p1 - p0, 2.0 / 250.0, &idepth));
  EXPECT_TRUE(
      RayLineInverseDepth(camera, mid_px + 1.0 * normal_px, p0, p1 - p0, 2.0 / 250.0, &idepth));
  // Near-parallel (the line along the ray) and behind the camera.
  const Eigen::Vector3d ray = camera.Unproject(Eigen::Vector2d(100, 80));
  EXPECT_FALSE(RayLineInverseDepth(camera, Eigen::Vector2d(100, 80), p0, ray, 1e-3, &idepth));
  EXPECT_FALSE(RayLineInverseDepth(camera, Eigen::Vector2d(100, 80), -p0, Eigen::Vector3d::UnitX(),
                                   1.0, &idepth));
}

// (a) var = J Sigma J^T against 10 000 samples of the tangent perturbation. The sample variance
// of 10 000 Gaussian samples has a relative standard error sqrt(2 / 9999) = 1.4 %; the rest of
// the 10 % budget is for the second-order terms of the intersection (sigma / depth ~ 1 %).
TEST(EdgeBALineDepthTest, VarianceMatchesMonteCarlo) {
  const PinholeCamera camera = TestCamera();
  KeyframeLine line;
  line.edge_id = 0;
  line.point = 3.0 * camera.Unproject(Eigen::Vector2d(90, 60));
  line.direction = (3.5 * camera.Unproject(Eigen::Vector2d(230, 170)) - line.point).normalized();
  line.tangent_covariance = TestCovariance();
  const Eigen::Vector2d pixel = camera.Project(line.point + 0.8 * line.direction);
  double idepth = 0.0, idepth_var = 0.0;
  ASSERT_TRUE(RayLineInverseDepthAndVariance(camera, pixel, line, 1e-3, &idepth, &idepth_var));
  EXPECT_GT(idepth_var, 0.0);
  const double sampled =
      MonteCarloVariance(line, line.tangent_covariance, 10000,
                         [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
                           double value = 0.0;
                           EXPECT_TRUE(RayLineInverseDepth(camera, pixel, o, d, 1e300, &value));
                           return value;
                         });
  EXPECT_NEAR(idepth_var / sampled, 1.0, 0.10) << idepth_var << " vs " << sampled;
}

// The covariance in the camera frame (G Sigma_w G^T) against sampling in the world and moving the
// samples: the variance of the inverse depth must agree whichever frame it is propagated in.
TEST(EdgeBALineDepthTest, CovarianceChangesFrameConsistently) {
  const PinholeCamera camera = TestCamera();
  const SE3 cam_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(0.3, -0.2, 0.5));
  const SE3 world_from_cam = cam_from_world.Inverse();
  KeyframeLine world;
  world.point = world_from_cam * (3.0 * camera.Unproject(Eigen::Vector2d(90, 60)));
  world.direction = world_from_cam.rotation() * Eigen::Vector3d(1.0, 0.6, 0.2).normalized();
  world.tangent_covariance = TestCovariance();
  const KeyframeLine in_cam =
      LineInCamera(cam_from_world, world.point, world.direction, world.tangent_covariance, 4);
  EXPECT_EQ(in_cam.edge_id, 4);
  const Eigen::Vector2d pixel = camera.Project(in_cam.point + 0.5 * in_cam.direction);
  double idepth = 0.0, idepth_var = 0.0;
  ASSERT_TRUE(RayLineInverseDepthAndVariance(camera, pixel, in_cam, 1e-3, &idepth, &idepth_var));
  const double sampled = MonteCarloVariance(
      world, world.tangent_covariance, 10000,
      [&](const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
        double value = 0.0;
        EXPECT_TRUE(RayLineInverseDepth(camera, pixel, cam_from_world * o,
                                        cam_from_world.rotation() * d, 1e300, &value));
        return value;
      });
  // Same budget as above.
  EXPECT_NEAR(idepth_var / sampled, 1.0, 0.10) << idepth_var << " vs " << sampled;
}

// (b) A keyframe whose edge 0 (row 120, x in [40, 280)) has the wrong depth 2 m, and a known 3D
// line through its rays (depth 3 m at x = 40 to 4 m at x = 280) with a small covariance: the
// edge moves to the line's depths. Edge 1 (row 60) has no line and keeps its depth. A second,
// far-off line for the now confident edge 0 is rejected by the EKF gate.
TEST(EdgeBALineDepthTest, DepthMapperMovesEdgeToLineDepths) {
  const PinholeCamera camera = TestCamera();
  MappingOptions options;
  DepthMapper mapper(camera, options);
  const cv::Mat image(camera.height, camera.width, CV_32F, cv::Scalar(100.0f));  // no gradient
  EdgeTrace edges;
  edges.id_map = cv::Mat(camera.height, camera.width, CV_32S, cv::Scalar(-1));
  const int rows[2] = {120, 60};
  for (int e = 0; e < 2; ++e) {
    for (int x = 40; x < 280; ++x) edges.id_map.at<int>(rows[e], x) = e;
  }
  const cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(2.0f));
  // Inverse-depth sigma 0.3 (1/m): the line's 0.25-0.33 lies within the 2-sigma gate of 0.5.
  mapper.InitializeKeyframeFromDepth(image, edges, depth, 0.09);
  const SemiDenseDepthMap& map = mapper.depth_map();
  for (int e = 0; e < 2; ++e) ASSERT_TRUE(map.valid(map.Index(150, rows[e])));

  auto line_through_row = [&](int row, double z_left, double z_right, int edge_id) {
    const Eigen::Vector3d p0 = z_left * camera.Unproject(Eigen::Vector2d(40, row));
    const Eigen::Vector3d p1 = z_right * camera.Unproject(Eigen::Vector2d(279, row));
    KeyframeLine line;
    line.edge_id = edge_id;
    line.point = p0;
    line.direction = (p1 - p0).normalized();
    // Sigmas 1 mm / 0.06 deg: a well-constrained BA line.
    line.tangent_covariance = 1e-6 * Eigen::Matrix4d::Identity();
    return line;
  };
  const std::vector<KeyframeLine> lines = {line_through_row(120, 3.0, 4.0, 0)};
  const LineDepthFusionStats stats = mapper.FuseLineDepths(lines);
  EXPECT_EQ(stats.pixels, 240);  // every pixel of edge 0 is a valid candidate
  EXPECT_EQ(stats.fused, stats.pixels);
  EXPECT_EQ(stats.skipped, 0);
  EXPECT_EQ(stats.outliers, 0);
  for (int x = 40; x < 280; ++x) {
    const int i = map.Index(x, 120);
    double expected = 0.0;
    ASSERT_TRUE(RayLineInverseDepth(camera, Eigen::Vector2d(x, 120), lines[0].point,
                                    lines[0].direction, 1e-3, &expected));
    // Prior variance 0.09 against ~1e-6: the fused mean is within 1e-4 of the line's.
    EXPECT_NEAR(map.idepth(i), expected, 1e-4) << x;
    EXPECT_LT(map.idepth_var(i), 1e-4);
    EXPECT_NEAR(map.idepth(map.Index(x, 60)), 0.5, 1e-6);  // edge 1: no line, unchanged
  }
  // 8-10 m (idepth ~0.11) against a hypothesis of sigma < 0.01 at 0.25-0.33: outside the gate.
  const LineDepthFusionStats far = mapper.FuseLineDepths({line_through_row(120, 8.0, 10.0, 0)});
  EXPECT_EQ(far.outliers, 240);
  EXPECT_EQ(far.fused, 0);
}

// The BA's line covariances (ceres::Covariance after SolveEdgeBA) are consistent with the
// actual errors on a simulated window with Gaussian pixel noise: the tangent error e of each
// optimised line (Minus of the true line, its point taken nearest the estimate's, at the
// estimate) has e^T Sigma^-1 e ~ chi^2(4), so the mean NEES over the lines is ~4.
TEST(EdgeBALineDepthTest, SolverLineCovariancesAreConsistent) {
  const PinholeCamera camera = TestCamera();
  const EdgeBAScene scene = MakeRandomLineScene(60, 4, 0.3, 3);
  EdgeBASimulationOptions simulation_options;
  simulation_options.pixel_sigma = 0.5;
  const EdgeBASimulation simulation = SimulateEdgeBAWindow(
      camera, scene.world_from_cam, scene.start, scene.end, simulation_options);
  EdgeBAOptions options;
  options.robust_loss = RobustLossKind::kNone;  // Gaussian noise: the exact least squares
  options.max_iterations = 50;
  options.function_tolerance = 1e-12;
  const EdgeBAResult result = SolveEdgeBA(simulation.window, options);
  ASSERT_TRUE(result.success) << result.message;
  ASSERT_TRUE(result.covariance_ok);
  EXPECT_GT(result.covariance_seconds, 0.0);
  double nees_sum = 0.0;
  int num_lines = 0;
  for (const EdgeBAResultLine& line : result.lines) {
    if (line.status != EdgeBALineStatus::kOptimized) {
      EXPECT_FALSE(line.has_covariance);
      continue;
    }
    ASSERT_TRUE(line.has_covariance);
    const Eigen::Vector3d o = line.line.point_in_world, d = line.line.direction_in_world;
    const Eigen::Vector3d start = simulation.start_true[line.line.id];
    const Eigen::Vector3d d_true = (simulation.end_true[line.line.id] - start).normalized();
    const Eigen::Vector3d o_true = start + (o - start).dot(d_true) * d_true;
    // Either sign of the true direction; the one nearer the estimate.
    const Eigen::Vector3d d_near = d_true.dot(d) >= 0.0 ? d_true : Eigen::Vector3d(-d_true);
    const double x[6] = {o.x(), o.y(), o.z(), d.x(), d.y(), d.z()};
    const double y[6] = {o_true.x(), o_true.y(), o_true.z(), d_near.x(), d_near.y(), d_near.z()};
    Eigen::Vector4d error;
    ceres::LineManifold<3>().Minus(y, x, error.data());
    nees_sum += error.dot(line.tangent_covariance.ldlt().solve(error));
    ++num_lines;
  }
  ASSERT_GE(num_lines, 20);
  const double mean_nees = nees_sum / num_lines;
  // The mean of N chi^2(4) values has standard deviation sqrt(8 / N) <= 0.63 for N >= 20; the
  // band 4 +- 2 is about 3 sigma, and an unscaled or mis-whitened covariance (e.g. sigma_px
  // ignored: 4x) falls outside it.
  EXPECT_GT(mean_nees, 2.0) << num_lines << " lines";
  EXPECT_LT(mean_nees, 6.0) << num_lines << " lines";
  std::printf("mean NEES %.2f over %d lines, covariance %.1f ms\n", mean_nees, num_lines,
              1e3 * result.covariance_seconds);
}

}  // namespace
}  // namespace pldvo
