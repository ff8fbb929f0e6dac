// The cost functions and geometry of edge bundle adjustment: LineObservationResidual and
// BaselinePriorResidual (checked with ceres::GradientChecker through their manifolds), Ceres'
// LineManifold<3>, and the line triangulation from back-projected planes.
#include <ceres/gradient_checker.h>
#include <ceres/line_manifold.h>
#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "backend/edge_ba/edge_ba_line_triangulation.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/baseline_prior_residual.h"
#include "residuals/line_observation_residual.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

PinholeCamera Camera() { return PinholeCamera{640, 480, 520.0, 510.0, 319.5, 239.5}; }

SE3 CamFromWorld() {
  Vector6d twist;
  twist << 0.3, -0.2, 0.4, 0.15, -0.25, 0.1;
  return SE3::Exp(twist);
}

// A line 3-4 m in front of the camera of CamFromWorld().
void TestLine(double* line) {
  const SE3 world_from_cam = CamFromWorld().Inverse();
  const Eigen::Vector3d point = world_from_cam * Eigen::Vector3d(0.2, -0.1, 3.5);
  const Eigen::Vector3d direction =
      (world_from_cam.rotation() * Eigen::Vector3d(1.0, 0.3, 0.4)).normalized();
  for (int i = 0; i < 3; ++i) {
    line[i] = point(i);
    line[3 + i] = direction(i);
  }
}

// Pixels scattered up to 3 px around the projected line (residuals of a few sigma, so that
// Huber and Cauchy rows are on both sides of their thresholds).
std::vector<LineObservationPixel> NoisyPixels(const PinholeCamera& camera, const double* line,
                                              int count) {
  const SE3 cam_from_world = CamFromWorld();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> along(-0.8, 0.8), offset(-3.0, 3.0), info(0.5, 2.0);
  std::vector<LineObservationPixel> pixels;
  const Eigen::Vector3d o(line[0], line[1], line[2]);
  const Eigen::Vector3d d(line[3], line[4], line[5]);
  Eigen::Vector3d image_line;
  EXPECT_TRUE(ProjectLine(camera, cam_from_world, o, d, &image_line));
  while (static_cast<int>(pixels.size()) < count) {
    const Eigen::Vector2d on_line = camera.Project(cam_from_world * (o + along(rng) * d));
    LineObservationPixel p;
    const double distance = offset(rng);
    p.pixel = on_line + distance * image_line.head<2>();
    p.sqrt_info = info(rng);
    // The whitened residual is sqrt_info * distance. Keep it away from Huber's kink at 1.345,
    // where the second derivative jumps and Ridders' extrapolation loses its accuracy.
    const double whitened = std::abs(p.sqrt_info * distance);
    if (whitened > 1.1 && whitened < 1.6) continue;
    pixels.push_back(p);
  }
  return pixels;
}

std::unique_ptr<ceres::LossFunction> MakeLoss(int kind) {
  if (kind == 1) return std::make_unique<ceres::HuberLoss>(1.345);
  if (kind == 2) return std::make_unique<ceres::CauchyLoss>(1.0);
  return nullptr;
}

// GradientChecker with SE3Manifold and LineManifold<3>, Ridders from a 1e-5 relative step. The
// residual is a smooth double-precision function of the parameters, so Ridders' estimate is
// accurate to ~1e-9 relative; 1e-6 leaves margin for entries that nearly cancel.
TEST(LineObservationResidualTest, GradientChecker) {
  const PinholeCamera camera = Camera();
  double pose[7];
  PoseToParameters(CamFromWorld(), pose);
  double line[6];
  TestLine(line);
  const SE3Manifold pose_manifold;
  const ceres::LineManifold<3> line_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, &line_manifold};
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-5;
  for (int loss_kind = 0; loss_kind < 3; ++loss_kind) {
    const auto loss = MakeLoss(loss_kind);
    const LineObservationResidual cost(camera, NoisyPixels(camera, line, 20), loss.get());
    const ceres::GradientChecker checker(&cost, &manifolds, options);
    ceres::GradientChecker::ProbeResults results;
    const double* parameters[] = {pose, line};
    EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << "loss " << loss_kind << "\n"
                                                           << results.error_log;
  }
}

// The residual is sqrt_info times the signed pixel distance to the projection of the 3D line,
// computed independently here by projecting two of its points; it is invariant to the scale of
// the direction and to where on the line the point sits.
TEST(LineObservationResidualTest, IsWhitenedDistanceToProjectedLine) {
  const PinholeCamera camera = Camera();
  const SE3 cam_from_world = CamFromWorld();
  double pose[7];
  PoseToParameters(cam_from_world, pose);
  double line[6];
  TestLine(line);
  const Eigen::Vector3d o(line[0], line[1], line[2]);
  const Eigen::Vector3d d(line[3], line[4], line[5]);
  const Eigen::Vector2d p1 = camera.Project(cam_from_world * o);
  const Eigen::Vector2d p2 = camera.Project(cam_from_world * (o + 0.5 * d));
  const Eigen::Vector2d tangent = (p2 - p1).normalized();
  const Eigen::Vector2d normal(-tangent.y(), tangent.x());
  LineObservationPixel pixel;
  pixel.pixel = p1 + 40.0 * tangent + 2.5 * normal;  // 2.5 px off the line
  pixel.sqrt_info = 0.5;
  const LineObservationResidual cost(camera, {pixel});
  double residual;
  const double* parameters[] = {pose, line};
  ASSERT_TRUE(cost.Evaluate(parameters, &residual, nullptr));
  // Pixel coordinates are exact to ~1e-12 px here; 1e-9 is far below anything meaningful.
  EXPECT_NEAR(std::abs(residual), 0.5 * 2.5, 1e-9);
  double moved[6];
  for (int i = 0; i < 3; ++i) {
    moved[i] = o(i) - 2.7 * d(i);
    moved[3 + i] = 3.0 * d(i);
  }
  const double* moved_parameters[] = {pose, moved};
  double moved_residual;
  ASSERT_TRUE(cost.Evaluate(moved_parameters, &moved_residual, nullptr));
  EXPECT_NEAR(moved_residual, residual, 1e-9);
}

// A line through the camera centre has no image line: Evaluate fails instead of dividing by 0.
TEST(LineObservationResidualTest, LineThroughCentreFails) {
  const PinholeCamera camera = Camera();
  double pose[7];
  PoseToParameters(SE3(), pose);
  double line[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 1.0};
  const LineObservationResidual cost(camera, {LineObservationPixel{}});
  double residual;
  const double* parameters[] = {pose, line};
  EXPECT_FALSE(cost.Evaluate(parameters, &residual, nullptr));
}

TEST(LineObservationResidualTest, RejectsBadInput) {
  EXPECT_THROW(LineObservationResidual(Camera(), {}), std::invalid_argument);
  LineObservationPixel bad;
  bad.sqrt_info = -1.0;
  EXPECT_THROW(LineObservationResidual(Camera(), {bad}), std::invalid_argument);
}

// Tolerance as in the line test above.
TEST(BaselinePriorResidualTest, GradientChecker) {
  double pose_a[7], pose_b[7];
  PoseToParameters(CamFromWorld(), pose_a);
  Vector6d twist;
  twist << -0.2, 0.35, 0.1, -0.1, 0.2, 0.3;
  PoseToParameters(SE3::Exp(twist) * CamFromWorld(), pose_b);
  const BaselinePriorResidual cost(0.3, 0.01);
  const SE3Manifold manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&manifold, &manifold};
  ceres::NumericDiffOptions options;
  options.ridders_relative_initial_step_size = 1e-5;
  const ceres::GradientChecker checker(&cost, &manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  const double* parameters[] = {pose_a, pose_b};
  checker.Probe(parameters, 1e-6, &results);
  ASSERT_TRUE(results.return_value);
  // The rotational columns are exactly 0 analytically (the centre does not move under a
  // rotation about it) and ~1e-11 numerically, which the checker's per-entry relative test
  // flags; compare each entry against 1e-6 of its row's largest magnitude instead.
  for (int block = 0; block < 2; ++block) {
    const Eigen::MatrixXd& analytic = results.local_jacobians[block];
    const Eigen::MatrixXd& numeric = results.local_numeric_jacobians[block];
    const double scale = numeric.cwiseAbs().maxCoeff();
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-6 * scale) << results.error_log;
    // Zero up to the rounding of lifting through the manifold (J_ambient * PlusJacobian).
    EXPECT_LT(analytic.rightCols<3>().cwiseAbs().maxCoeff(), 1e-12 * scale);
  }
  // The residual is (|c_b - c_a| - b0) / sigma.
  const Eigen::Vector3d ca = CamFromWorld().Inverse().translation();
  const Eigen::Vector3d cb = (SE3::Exp(twist) * CamFromWorld()).Inverse().translation();
  double residual;
  ASSERT_TRUE(cost.Evaluate(parameters, &residual, nullptr));
  EXPECT_NEAR(residual, ((cb - ca).norm() - 0.3) / 0.01, 1e-9);
}

// Ceres 2.1's LineManifold<3> satisfies the manifold axioms at our kind of line (the test
// utility's own tolerance).
TEST(LineManifoldTest, InvariantsHold) {
  using namespace ceres;  // NOLINT: the macro names Ceres' matchers unqualified
  const ceres::LineManifold<3> manifold;
  double line[6];
  TestLine(line);
  const Eigen::Map<const Eigen::VectorXd> x(line, 6);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd delta(4);
    for (int i = 0; i < 4; ++i) delta(i) = noise(rng);
    Eigen::VectorXd y(6);
    manifold.Plus(line, delta.data(), y.data());
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-10);
  }
}

// Noise-free observations from three cameras: the planes meet in the true line (1e-9: double
// precision through one SVD of a 3x4 matrix of unit-scale entries).
TEST(LineTriangulationTest, RecoversLineFromPlanes) {
  const PinholeCamera camera = Camera();
  double line[6];
  TestLine(line);
  const Eigen::Vector3d o(line[0], line[1], line[2]);
  const Eigen::Vector3d d(line[3], line[4], line[5]);
  std::vector<WorldPlane> planes;
  for (int k = 0; k < 3; ++k) {
    Vector6d twist;
    twist << 0.2 * k, -0.1 * k, 0.05 * k, 0.02 * k, 0.03 * k, -0.01 * k;
    const SE3 cam_from_world = SE3::Exp(twist) * CamFromWorld();
    std::vector<Eigen::Vector2d> pixels;
    for (double s : {-0.5, -0.1, 0.3, 0.6})
      pixels.push_back(camera.Project(cam_from_world * (o + s * d)));
    WorldPlane plane;
    ASSERT_TRUE(BackProjectedPlane(camera, cam_from_world, pixels, &plane));
    EXPECT_NEAR(plane.normal.dot(o) + plane.offset, 0.0, 1e-9);
    EXPECT_NEAR(plane.normal.dot(d), 0.0, 1e-9);
    planes.push_back(plane);
  }
  EXPECT_GT(LargestPlaneAngle(planes), 0.01);
  Eigen::Vector3d point, direction;
  ASSERT_TRUE(IntersectPlanes(planes, &point, &direction));
  EXPECT_NEAR(std::abs(direction.dot(d)), 1.0, 1e-9);
  EXPECT_NEAR(((point - o) - d * d.dot(point - o)).norm(), 0.0, 1e-9);
  // One plane twice: no line.
  EXPECT_FALSE(IntersectPlanes({planes[0], planes[0]}, &point, &direction));
}

}  // namespace
}  // namespace pldvo
