// Line-guided stereo (backend/mapping/line_stereo.h): the plane-intersection triangulation of eqs.
// 8-9 is exact on noiseless geometry, and the disparity variance of eq. 10 (both edges' parts)
// matches Monte Carlo sampling.
#include "backend/mapping/line_stereo.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "core/random_draws.h"
#include "residuals/covariance_models.h"

namespace pldvo {
namespace {

PinholeCamera TestCamera() { return PinholeCamera{640, 480, 500.0, 510.0, 319.5, 239.5}; }

// The image line through the projections of two 3D points (a^2 + b^2 = 1).
Eigen::Vector3d ProjectLine(const PinholeCamera& camera, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b) {
  const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
  const Eigen::Vector3d l =
      Eigen::Vector3d(pa.x(), pa.y(), 1.0).cross(Eigen::Vector3d(pb.x(), pb.y(), 1.0));
  return l / l.head<2>().norm();
}

// The sample variance of the inverse depths of `samples` line-guided observations, each made by
// observe(&observation); every one must succeed.
template <class Observe>
double IdepthSampleVariance(int samples, Observe observe) {
  double sum = 0.0, sum_sq = 0.0;
  int failed = 0;
  for (int k = 0; k < samples; ++k) {
    StereoObservation observation;
    if (observe(&observation) != StereoStatus::kOk) {
      ++failed;
      continue;
    }
    sum += observation.idepth;
    sum_sq += observation.idepth * observation.idepth;
  }
  EXPECT_EQ(failed, 0);
  const int n = samples - failed;
  const double mean = sum / n;
  return sum_sq / n - mean * mean;
}

TEST(LineStereoTest, PlaneIntersectionIsExactOnNoiselessGeometry) {
  const PinholeCamera camera = TestCamera();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int tested = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const SE3 cur_from_ref = SE3::Exp((Vector6d() << 0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng),
                                       0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng))
                                          .finished());
    const Eigen::Vector3d ra = DrawVector3(u, rng), rb = DrawVector3(u, rng);
    const Eigen::Vector3d a(ra.x(), ra.y(), 3.0 + ra.z()), b(rb.x(), rb.y(), 3.0 + rb.z());
    if ((cur_from_ref * a).z() < 0.5 || (cur_from_ref * b).z() < 0.5) continue;
    const Eigen::Vector3d l1 = ProjectLine(camera, a, b);
    const Eigen::Vector3d l2 = ProjectLine(camera, cur_from_ref * a, cur_from_ref * b);
    Line3d line;
    // Lines (nearly) in the epipolar plane are degenerate; their planes coincide.
    if (!TriangulateLine(BackProjectedPlanes(l1, l2, camera, cur_from_ref), &line)) continue;
    const EpipolarGeometry geometry(camera, cur_from_ref);
    // Skip near-degenerate configurations (epipolar plane within ~1 deg of the line).
    const Eigen::Vector2d pa = camera.Project(a);
    double unused;
    if (!IdepthFromLinePlane(geometry, pa, l2, &unused)) continue;
    const double sin_angle =
        std::abs(l2.head<2>().dot(geometry.IdepthJacobian(pa, 1.0 / a.z()).normalized()));
    if (sin_angle < 0.02) continue;
    ++tested;
    // Both endpoints on the triangulated line; 1e-9 m is round-off for metre-scale values.
    for (const Eigen::Vector3d& p : {a, b}) {
      const Eigen::Vector3d offset = p - line.point_in_ref;
      EXPECT_LT((offset - offset.dot(line.direction) * line.direction).norm(), 1e-8);
    }
    EXPECT_GT(std::abs(line.direction.dot((b - a).normalized())), 1.0 - 1e-12);
    // Eq. 9: the inverse depth of pixels on l1 from the plane of l2 equals the true one.
    for (double s : {0.0, 0.3, 0.7, 1.0}) {
      const Eigen::Vector3d p = a + s * (b - a);
      double idepth = 0.0;
      ASSERT_TRUE(IdepthFromLinePlane(geometry, camera.Project(p), l2, &idepth));
      EXPECT_NEAR(idepth, 1.0 / p.z(), 1e-9 / p.z() / sin_angle);
    }
  }
  EXPECT_GT(tested, 150);
}

TEST(LineStereoTest, ParallelEdgeIsIllConditioned) {
  const PinholeCamera camera = TestCamera();
  // Pure x translation: horizontal epipolar lines; a horizontal edge is parallel to them.
  const SE3 cur_from_ref(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1, 0.0, 0.0));
  const EpipolarGeometry geometry(camera, cur_from_ref);
  LineWithCovariance line = FitLine(Eigen::Vector2d(100, 200.2), Eigen::Vector2d(300, 200.4), 0.5);
  MappingOptions options;
  StereoObservation observation;
  EXPECT_EQ(LineGuidedStereo(geometry, Eigen::Vector2d(200, 200), Eigen::Vector2d(200, 200), 0.0,
                             line, 0.0, 5.0, options, nullptr, nullptr, &observation),
            StereoStatus::kLineIllConditioned);
}

// Eq. 10 against the sample variance of the exact intersection of an epipolar line (offset
// N(0, sigma_g^2) across itself) and an edge fitted through noisy endpoints (N(0, sigma_px^2)).
// 20 000 samples give a relative standard error of the variance of sqrt(2 / N) = 1%; the
// first-order model's own error at sigma_px = 0.5 px on a 60 px edge is a few percent at the
// smallest angle, so 10% (the brief's tolerance) leaves margin for both.
TEST(LineStereoTest, DisparityVarianceMatchesMonteCarlo) {
  const double sigma_px = 0.5, sigma_g = 0.3;
  const int kSamples = 20000;
  for (double theta_deg : {20.0, 45.0, 70.0, 90.0}) {
    const double theta = theta_deg * M_PI / 180.0;
    // Epipolar line: y = 0, direction +x. Edge through the match (50, 0) at angle theta; the
    // segment is centred 15 px from the match so that the line's angle error matters.
    const Eigen::Vector2d match(50.0, 0.0), dir(std::cos(theta), std::sin(theta));
    const Eigen::Vector2d p1 = match + (15.0 - 30.0) * dir, p2 = match + (15.0 + 30.0) * dir;
    const LineWithCovariance fitted = FitLine(p1, p2, sigma_px);
    const Eigen::Vector3d match_h(match.x(), match.y(), 1.0);
    const double predicted =
        LineDisparityVar(match_h.dot(fitted.cov * match_h), sigma_g * sigma_g, theta);
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    double sum = 0.0, sum_sq = 0.0;
    for (int k = 0; k < kSamples; ++k) {
      const Eigen::Vector2d q1 = p1 + sigma_px * DrawVector2(noise, rng);
      const Eigen::Vector2d q2 = p2 + sigma_px * DrawVector2(noise, rng);
      const double offset = sigma_g * noise(rng);
      // Intersection of y = offset with the line through q1, q2.
      const double s = (offset - q1.y()) / (q2.y() - q1.y());
      const double x = q1.x() + s * (q2.x() - q1.x());
      sum += x;
      sum_sq += x * x;
    }
    const double mean = sum / kSamples;
    const double sample_var = sum_sq / kSamples - mean * mean;
    EXPECT_NEAR(sample_var / predicted, 1.0, 0.10) << "theta " << theta_deg << " deg";
  }
}

// The full line-guided observation (intersection, alpha conversion to inverse depth) against
// Monte Carlo over noisy current lines; same tolerance reasoning as above.
TEST(LineStereoTest, IdepthVarianceMatchesMonteCarlo) {
  const PinholeCamera camera = TestCamera();
  const SE3 cur_from_ref = SE3::Exp((Vector6d() << 0.12, 0.03, 0.02, 0.01, -0.02, 0.01).finished());
  const EpipolarGeometry geometry(camera, cur_from_ref);
  const Eigen::Vector3d a(-0.4, -0.5, 2.5), b(0.3, 0.6, 2.8);  // a steep 3D edge
  const Eigen::Vector3d point = a + 0.4 * (b - a);
  const Eigen::Vector2d pixel = camera.Project(point);
  const Eigen::Vector2d c1 = camera.Project(cur_from_ref * a),
                        c2 = camera.Project(cur_from_ref * b);
  const double sigma_px = 0.5;
  MappingOptions options;
  options.sigma_epipolar_px = 0.0;  // only the line noise is sampled
  StereoObservation nominal;
  ASSERT_EQ(LineGuidedStereo(geometry, pixel, pixel, 0.0, FitLine(c1, c2, sigma_px), 0.0, 5.0,
                             options, nullptr, nullptr, &nominal),
            StereoStatus::kOk);
  EXPECT_NEAR(nominal.idepth, 1.0 / point.z(), 1e-3);  // endpoints noise-free here
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, sigma_px);
  const double sample_var = IdepthSampleVariance(20000, [&](StereoObservation* observation) {
    const Eigen::Vector2d q1 = c1 + DrawVector2(noise, rng);
    const Eigen::Vector2d q2 = c2 + DrawVector2(noise, rng);
    return LineGuidedStereo(geometry, pixel, pixel, 0.0, FitLine(q1, q2, sigma_px), 0.0, 5.0,
                            options, nullptr, nullptr, observation);
  });
  EXPECT_NEAR(sample_var / nominal.idepth_var, 1.0, 0.10);
}

// The keyframe edge's part of eq. 10: a traced pixel 0.7 px off the edge is matched from its foot
// point on a keyframe line fitted through noisy endpoints. Noise on the keyframe endpoints alone
// must give the observation's shared variance, and noise on both lines its whole variance (same
// tolerance reasoning as above).
TEST(LineStereoTest, KeyframeEdgeVarianceMatchesMonteCarlo) {
  const PinholeCamera camera = TestCamera();
  const SE3 cur_from_ref = SE3::Exp((Vector6d() << 0.12, 0.03, 0.02, 0.01, -0.02, 0.01).finished());
  const EpipolarGeometry geometry(camera, cur_from_ref);
  const Eigen::Vector3d a(-0.4, -0.5, 2.5), b(0.3, 0.6, 2.8);
  const Eigen::Vector2d k1 = camera.Project(a), k2 = camera.Project(b);
  const Eigen::Vector2d c1 = camera.Project(cur_from_ref * a),
                        c2 = camera.Project(cur_from_ref * b);
  const LineWithCovariance exact_l1 = FitLine(k1, k2, 0.5);
  const Eigen::Vector2d pixel = k1 + 0.4 * (k2 - k1) + 0.7 * exact_l1.line.head<2>();
  MappingOptions options;
  options.sigma_epipolar_px = 0.0;
  // Foot point of `pixel` on l1 and l1's perpendicular variance there.
  auto foot_point = [&](const LineWithCovariance& l1, double* var) {
    const Eigen::Vector2d foot =
        pixel -
        (l1.line.x() * pixel.x() + l1.line.y() * pixel.y() + l1.line.z()) * l1.line.head<2>();
    const Eigen::Vector3d foot_h(foot.x(), foot.y(), 1.0);
    *var = foot_h.dot(l1.cov * foot_h);
    return foot;
  };
  const double sigma_px = 0.5;
  double ref_var = 0.0;
  const Eigen::Vector2d nominal_foot = foot_point(exact_l1, &ref_var);
  StereoObservation nominal;
  ASSERT_EQ(LineGuidedStereo(geometry, pixel, nominal_foot, ref_var, FitLine(c1, c2, sigma_px), 0.0,
                             5.0, options, nullptr, nullptr, &nominal),
            StereoStatus::kOk);
  EXPECT_GT(nominal.shared_idepth_var, 0.3 * nominal.idepth_var);
  EXPECT_LT(nominal.shared_idepth_var, 0.7 * nominal.idepth_var);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (const bool noisy_current : {false, true}) {
    const double sample_var = IdepthSampleVariance(20000, [&](StereoObservation* observation) {
      const LineWithCovariance l1 =
          FitLine(k1 + DrawVector2(noise, rng), k2 + DrawVector2(noise, rng), sigma_px);
      Eigen::Vector2d q1 = c1, q2 = c2;
      if (noisy_current) {
        q1 += DrawVector2(noise, rng);
        q2 += DrawVector2(noise, rng);
      }
      double var = 0.0;
      const Eigen::Vector2d foot = foot_point(l1, &var);
      return LineGuidedStereo(geometry, pixel, foot, var, FitLine(q1, q2, sigma_px), 0.0, 5.0,
                              options, nullptr, nullptr, observation);
    });
    const double ratio =
        sample_var / (noisy_current ? nominal.idepth_var : nominal.shared_idepth_var);
    const char* noisy = noisy_current ? "both lines" : "keyframe line";
    std::printf("%s noisy: sample / predicted variance %.3f (shared fraction %.3f)\n", noisy, ratio,
                nominal.shared_idepth_var / nominal.idepth_var);
    EXPECT_NEAR(ratio, 1.0, 0.10) << noisy << " noisy";
  }
}

}  // namespace
}  // namespace pldvo
