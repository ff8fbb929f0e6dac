#include "core/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include "core/random_draws.h"

namespace pldvo {
namespace {

// Every expected value below is exact in real arithmetic; 1e-9 leaves room for the rounding of
// an SVD and of sums over a few hundred poses (errors near 1e-13).
constexpr double kTolerance = 1e-9;

StampedPose Pose(double t, const Eigen::Vector3d& position,
                 const Eigen::Quaterniond& rotation = Eigen::Quaterniond::Identity()) {
  StampedPose pose;
  pose.timestamp = t;
  pose.world_from_cam = SE3(rotation, position);
  return pose;
}

EvaluationOptions SkippingConstantVelocityStart() {
  EvaluationOptions options;
  options.skip_constant_velocity_start = true;
  return options;
}

// A smooth non-planar path (so the alignment is unique) with a turning camera, 10 Hz.
Trajectory CurvedTrajectory(int n) {
  Trajectory trajectory;
  for (int i = 0; i < n; ++i) {
    const double t = 0.1 * i;
    trajectory.push_back(Pose(
        t, Eigen::Vector3d(std::cos(0.3 * t), std::sin(0.5 * t), 0.2 * t),
        Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * t, Eigen::Vector3d(0.3, 1, 0.2).normalized()))));
  }
  return trajectory;
}

// world' = s R world + t applied to a trajectory (positions scaled, orientations rotated).
Trajectory Transform(const Trajectory& trajectory, double s, const Eigen::Matrix3d& rotation,
                     const Eigen::Vector3d& translation) {
  Trajectory out;
  for (const StampedPose& pose : trajectory) {
    out.push_back(Pose(pose.timestamp,
                       s * rotation * pose.world_from_cam.translation() + translation,
                       Eigen::Quaterniond(rotation) * pose.world_from_cam.rotation()));
  }
  return out;
}

TEST(AlignUmeyama, RecoversAKnownSimilarity) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Vector3d> src, dst;
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d translation(3, -1, 7);
  for (int i = 0; i < 20; ++i) {
    src.push_back(DrawVector3(normal, rng));
    dst.push_back(0.3 * rotation * src.back() + translation);
  }
  const Sim3Alignment alignment = AlignUmeyama(src, dst);
  EXPECT_NEAR(alignment.scale, 0.3, kTolerance);
  EXPECT_LT((alignment.rotation - rotation).norm(), kTolerance);
  EXPECT_LT((alignment.translation - translation).norm(), kTolerance);
}

TEST(AlignUmeyama, ReflectionIsNotReturned) {
  // dst is a mirror image of src: the best proper rotation has det +1 (Umeyama's S matrix).
  std::vector<Eigen::Vector3d> src = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {-1, 2, 0}};
  std::vector<Eigen::Vector3d> dst;
  for (const auto& p : src) dst.emplace_back(p.x(), p.y(), -p.z());
  const Sim3Alignment alignment = AlignUmeyama(src, dst);
  EXPECT_NEAR(alignment.rotation.determinant(), 1.0, kTolerance);
}

TEST(AlignUmeyama, DegenerateInputsThrow) {
  EXPECT_THROW(AlignUmeyama({{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {1, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(AlignUmeyama({{1, 1, 1}, {1, 1, 1}, {1, 1, 1}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}),
               std::invalid_argument);
}

TEST(EvaluateTrajectory, HalfScaleEstimateHasScaleTwoAndZeroAte) {
  const Trajectory gt = CurvedTrajectory(100);
  const Trajectory est = Transform(gt, 0.5, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_NEAR(result.scale, 2.0, kTolerance);
  EXPECT_NEAR(result.ate_m, 0.0, kTolerance);
  EXPECT_NEAR(result.rpe_cm_s, 0.0, kTolerance);
  EXPECT_NEAR(result.rpe_deg_s, 0.0, kTolerance);
  EXPECT_EQ(result.num_associated, 100);
  EXPECT_NEAR(result.coverage, 1.0, kTolerance);
  // 9.9 s of steps in 1 s windows, each at half the ground truth's length: no drift.
  ASSERT_EQ(result.window_scales.size(), 10u);
  for (double scale : result.window_scales) EXPECT_NEAR(scale, 0.5, kTolerance);
  EXPECT_NEAR(result.scale_drift, 1.0, kTolerance);
}

TEST(EvaluateTrajectory, WindowScalesFollowAScaleDriftAndSkipWindowsWithoutMotion) {
  // Ground truth at rest for the first second, then moving. The estimate repeats its steps at
  // 0.5 of their length up to t = 5 s and at 0.25 after (a monocular scale that halves).
  Trajectory gt = CurvedTrajectory(100);
  for (int i = 0; i < 10; ++i) gt[i] = Pose(gt[i].timestamp, gt[10].world_from_cam.translation());
  Trajectory est = {Pose(0.0, 0.5 * gt[0].world_from_cam.translation())};
  for (int k = 0; k + 1 < 100; ++k) {
    const double step_scale = k < 50 ? 0.5 : 0.25;
    const Eigen::Vector3d step =
        gt[k + 1].world_from_cam.translation() - gt[k].world_from_cam.translation();
    est.push_back(
        Pose(gt[k + 1].timestamp, est.back().world_from_cam.translation() + step_scale * step));
  }
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  // Window 0 (steps starting in [0, 1) s) has no ground-truth motion and is left out.
  ASSERT_EQ(result.window_scales.size(), 9u);
  for (int w = 0; w < 9; ++w) {
    EXPECT_NEAR(result.window_scales[w], w + 1 < 5 ? 0.5 : 0.25, kTolerance) << "window " << w + 1;
  }
  EXPECT_NEAR(result.scale_drift, 2.0, kTolerance);

  EvaluationOptions options;
  options.scale_window = 0.0;
  EXPECT_THROW(EvaluateTrajectory(gt, est, options), std::invalid_argument);
}

TEST(EvaluateTrajectory, OffsetAndRotatedEstimateHasZeroAte) {
  const Trajectory gt = CurvedTrajectory(100);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(1.2, Eigen::Vector3d(0.2, 0.3, 1).normalized()).toRotationMatrix();
  const Trajectory est = Transform(gt, 1.0, rotation, Eigen::Vector3d(10, -4, 2));
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_NEAR(result.scale, 1.0, kTolerance);
  EXPECT_NEAR(result.ate_m, 0.0, kTolerance);
  EXPECT_NEAR(result.rpe_cm_s, 0.0, kTolerance);
  EXPECT_NEAR(result.rpe_deg_s, 0.0, kTolerance);
  EXPECT_LT((result.gt_from_est.rotation - rotation.transpose()).norm(), kTolerance);
}

TEST(EvaluateTrajectory, KnownPerPoseNoiseGivesKnownAte) {
  // est: the 8 corners (+-1, +-1, +-1) of a cube. gt = s R est + t + a xyz u: the noise a xyz u
  // has zero mean and is orthogonal to every coordinate of the corners (sum x^2 y z = 0), so the
  // Umeyama alignment is exactly (s, R, t) and every residual has norm |a xyz| = a.
  const double a = 0.05, s = 3.0;
  const Eigen::Vector3d u = Eigen::Vector3d(1, 2, -2) / 3.0;  // unit
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::Vector3d translation(1, 2, 3);
  Trajectory est, gt;
  int i = 0;
  for (int x : {-1, 1}) {
    for (int y : {-1, 1}) {
      for (int z : {-1, 1}) {
        const Eigen::Vector3d p(x, y, z);
        est.push_back(Pose(i, p));
        gt.push_back(Pose(i, s * rotation * p + translation + a * x * y * z * u));
        ++i;
      }
    }
  }
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_NEAR(result.scale, s, kTolerance);
  EXPECT_NEAR(result.ate_m, a, kTolerance);
  EXPECT_EQ(result.num_associated, 8);
}

TEST(EvaluateTrajectory, RpeOfConstantVelocityWithKnownHeadingDrift) {
  // gt: 1 m/s along x for 10 s at 10 Hz, camera orientation identity. est: the same positions
  // at half scale, but the camera yawed by a constant theta, so every relative motion is seen
  // rotated: the relative translation over 1 s, scaled back by s = 2, is Rz(-theta) (1, 0, 0) and
  // differs from gt's (1, 0, 0) by 2 sin(theta / 2) m; the relative rotations agree (0 deg/s).
  const double theta = 2.0 * std::asin(0.05);  // 2 sin(theta/2) = 0.1 m per 1 s = 10 cm/s
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  Trajectory gt, est;
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.1 * i;
    gt.push_back(Pose(t, Eigen::Vector3d(t, 0, 0)));
    est.push_back(Pose(t, Eigen::Vector3d(0.5 * t, 0, 0), yaw));
  }
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_NEAR(result.scale, 2.0, kTolerance);
  EXPECT_NEAR(result.ate_m, 0.0, kTolerance);
  EXPECT_NEAR(result.rpe_cm_s, 10.0, 1e-7);
  EXPECT_NEAR(result.rpe_deg_s, 0.0, 1e-7);
  // Pairs (i, i + 10) for i = 0..90.
  EXPECT_EQ(result.num_pairs, 91);
  // The ground truth is one constant velocity throughout: reported, and evaluated whole even
  // when its start is to be skipped.
  EXPECT_EQ(result.constant_velocity_start_poses, 101);
  const EvaluationResult skipped = EvaluateTrajectory(gt, est, SkippingConstantVelocityStart());
  EXPECT_EQ(skipped.skipped_ground_truth_poses, 0);
  EXPECT_NEAR(skipped.rpe_cm_s, 10.0, 1e-7);
}

TEST(EvaluateTrajectory, SkippingAConstantVelocityStartEvaluatesFromItsLastPose) {
  // gt: 15 poses at one velocity (1 m/s along z, 10 Hz), then a curve. est: exact from pose 14
  // on, but 20% slower over the start (as an estimate that finds the acceleration the
  // extrapolated ground truth lacks). Whole: the start's error shows; skipped: RPE and ATE 0
  // over the 26 poses from pose 14, which is kept as the first.
  Trajectory gt, est;
  for (int i = 0; i < 40; ++i) {
    const double t = 0.1 * i;
    const double s = t - 1.4;  // time since pose 14
    const Eigen::Vector3d p =
        i <= 14 ? Eigen::Vector3d(0, 0, t) : Eigen::Vector3d(0.3 * s * s, 0.1 * s * s * s, 1.4 + s);
    gt.push_back(Pose(t, p));
    est.push_back(Pose(t, i <= 14 ? Eigen::Vector3d(0, 0, 1.4 + 0.8 * s) : p));
  }
  const EvaluationResult whole = EvaluateTrajectory(gt, est);
  EXPECT_EQ(whole.constant_velocity_start_poses, 15);
  EXPECT_EQ(whole.skipped_ground_truth_poses, 0);
  EXPECT_EQ(whole.num_associated, 40);
  EXPECT_GT(whole.rpe_cm_s, 5.0);
  const EvaluationResult skipped = EvaluateTrajectory(gt, est, SkippingConstantVelocityStart());
  EXPECT_EQ(skipped.constant_velocity_start_poses, 15);
  EXPECT_EQ(skipped.skipped_ground_truth_poses, 14);
  EXPECT_EQ(skipped.num_associated, 26);
  EXPECT_NEAR(skipped.rpe_cm_s, 0.0, 1e-7);
  EXPECT_NEAR(skipped.ate_m, 0.0, kTolerance);
  EXPECT_NEAR(skipped.coverage, 1.0, kTolerance);
}

TEST(EvaluateTrajectory, RpeOfConstantRotationalDrift) {
  // Positions identical, the estimate's camera turning at 2 deg/s about z more than gt's: the
  // rotational RPE is 2 deg/s for every pair.
  const double rate = 2.0 * M_PI / 180.0;
  Trajectory gt, est;
  for (int i = 0; i <= 50; ++i) {
    const double t = 0.1 * i;
    const Eigen::Vector3d p(std::cos(t), std::sin(t), 0.1 * t * t);
    gt.push_back(Pose(t, p));
    est.push_back(
        Pose(t, p, Eigen::Quaterniond(Eigen::AngleAxisd(rate * t, Eigen::Vector3d::UnitZ()))));
  }
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_NEAR(result.rpe_deg_s, 2.0, 1e-7);
  EXPECT_NEAR(result.ate_m, 0.0, kTolerance);
}

TEST(EvaluateTrajectory, StillRpeIsTheGroundTruthsOwnMotionWhichAStillEstimateScores) {
  // gt: 1 m/s along x for 10 s at 10 Hz, the camera turning about z at 0.2 rad/s. Every 1 s pair
  // moves 1 m whatever the turn: the still figure is 100 cm/s, for an exact estimate (RPE 0) as
  // for one that only turns (RPE 100 cm/s, rotation exact). The turning-only estimate stands at
  // the origin up to 1e-9 m (no alignment can place identical points) and is aligned without
  // scale.
  Trajectory gt, turning_only;
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.1 * i;
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.2 * t, Eigen::Vector3d::UnitZ()));
    gt.push_back(Pose(t, Eigen::Vector3d(t, 0, 0), turn));
    turning_only.push_back(Pose(t, 1e-9 * Eigen::Vector3d(i % 2, i % 3, i % 5), turn));
  }
  const EvaluationResult exact = EvaluateTrajectory(gt, gt);
  EXPECT_NEAR(exact.rpe_cm_s, 0.0, 1e-7);
  EXPECT_NEAR(exact.rpe_cm_s_still, 100.0, 1e-7);
  EvaluationOptions no_scale;
  no_scale.align_scale = false;
  const EvaluationResult still = EvaluateTrajectory(gt, turning_only, no_scale);
  EXPECT_EQ(still.num_pairs, 91);
  EXPECT_NEAR(still.rpe_cm_s, 100.0, 1e-5);
  EXPECT_NEAR(still.rpe_cm_s_still, 100.0, 1e-7);
  EXPECT_NEAR(still.rpe_deg_s, 0.0, 1e-7);
}

TEST(EvaluateTrajectory, CoverageCountsDroppedFrames) {
  // 100 gt poses at 10 Hz; the estimate loses 20 frames in the middle (tracking failure): 80
  // associated poses of 0.1 s over a 9.9 + 0.1 s span, coverage 0.8. The remaining poses are
  // exact, so ATE stays 0: coverage is what reports the loss.
  const Trajectory gt = CurvedTrajectory(100);
  Trajectory est;
  for (int i = 0; i < 100; ++i) {
    if (i < 40 || i >= 60) est.push_back(gt[i]);
  }
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_EQ(result.num_associated, 80);
  EXPECT_NEAR(result.coverage, 0.8, kTolerance);
  EXPECT_NEAR(result.ate_m, 0.0, kTolerance);

  // Lost after 25 frames and never recovered: coverage 0.25.
  const Trajectory short_est(gt.begin(), gt.begin() + 25);
  EXPECT_NEAR(EvaluateTrajectory(gt, short_est).coverage, 0.25, kTolerance);
}

TEST(EvaluateTrajectory, AssociationRespectsMaxTimeDifference) {
  // Estimate stamps offset by 0.015 s (associated) and 0.03 s (not, > 0.02 s).
  const Trajectory gt = CurvedTrajectory(30);
  Trajectory est;
  for (int i = 0; i < 30; ++i) {
    StampedPose pose = gt[i];
    pose.timestamp += (i % 2 == 0) ? 0.015 : 0.03;
    est.push_back(pose);
  }
  const EvaluationResult result = EvaluateTrajectory(gt, est);
  EXPECT_EQ(result.num_associated, 15);
  EXPECT_NEAR(result.ate_m, 0.0, kTolerance);
}

TEST(EvaluateTrajectory, TooFewAssociatedPosesThrow) {
  const Trajectory gt = CurvedTrajectory(30);
  Trajectory est = {Pose(100.0, {0, 0, 0}), Pose(101.0, {1, 0, 0}), Pose(102.0, {0, 1, 0})};
  EXPECT_THROW(EvaluateTrajectory(gt, est), std::invalid_argument);
}

TEST(EvaluateTrajectory, ShortEstimateHasNoRpePairs) {
  const Trajectory gt = CurvedTrajectory(8);  // 0.7 s < rpe_delta
  const EvaluationResult result = EvaluateTrajectory(gt, gt);
  EXPECT_EQ(result.num_pairs, 0);
  EXPECT_TRUE(std::isnan(result.rpe_cm_s));
  EXPECT_TRUE(std::isnan(result.rpe_cm_s_still));
}

TEST(EvaluateFrameMotion, AYawOfOneFrameShowsInTheTwoMotionsAroundIt) {
  // gt: 0.1 m per frame along x, camera orientation identity. est: the same path at half scale
  // (scale 2), but pose 2 yawed by theta. Motion 1 -> 2: rotation error theta, translation along
  // x in camera 1 for both (direction 0, ratio 2 * 0.05 / 0.1 = 1). Motion 2 -> 3: rotation error
  // theta, est translation Rz(-theta) (0.05, 0, 0) in camera 2: direction error theta. Motions
  // 0 -> 1 and 3 -> 4 are exact.
  const double theta = 2.0 * M_PI / 180.0;
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  Trajectory gt, est;
  for (int i = 0; i < 5; ++i) {
    gt.push_back(Pose(0.1 * i, Eigen::Vector3d(0.1 * i, 0, 0)));
    est.push_back(Pose(0.1 * i, Eigen::Vector3d(0.05 * i, 0, 0),
                       i == 2 ? yaw : Eigen::Quaterniond::Identity()));
  }
  const std::vector<FrameMotionError> errors = EvaluateFrameMotion(gt, est, 2.0, 0.02);
  ASSERT_EQ(errors.size(), 4u);
  const double expected_rotation[] = {0.0, 2.0, 2.0, 0.0};
  const double expected_direction[] = {0.0, 0.0, 2.0, 0.0};
  for (int m = 0; m < 4; ++m) {
    SCOPED_TRACE(m);
    EXPECT_NEAR(errors[m].timestamp, 0.1 * (m + 1), kTolerance);
    EXPECT_NEAR(errors[m].rotation_error_deg, expected_rotation[m], kTolerance);
    EXPECT_NEAR(errors[m].translation_direction_error_deg, expected_direction[m], 1e-6);
    EXPECT_NEAR(errors[m].translation_ratio, 1.0, kTolerance);
  }
}

TEST(EvaluateFrameMotion, ReportsTheAngleBetweenTranslationsAndSkipsPosesWithoutGroundTruth) {
  // gt moves along x, then stands still; est moves along y (90 deg off), then forward-backward
  // (180 deg). The estimate pose at t = 0.15 has no ground truth: the motions 0.1 -> 0.15 and
  // 0.15 -> 0.2 are left out, not bridged.
  Trajectory gt, est;
  for (int i = 0; i < 5; ++i)
    gt.push_back(Pose(0.1 * i, Eigen::Vector3d(std::min(i, 3), 0.0, 0.0)));
  est.push_back(Pose(0.0, Eigen::Vector3d(0, 0, 0)));
  est.push_back(Pose(0.1, Eigen::Vector3d(0, 1, 0)));
  est.push_back(Pose(0.15, Eigen::Vector3d(0, 1.5, 0)));
  est.push_back(Pose(0.2, Eigen::Vector3d(0, 2, 0)));
  est.push_back(Pose(0.3, Eigen::Vector3d(0, 3, 0)));
  est.push_back(Pose(0.4, Eigen::Vector3d(0, 3, 0)));
  const std::vector<FrameMotionError> errors = EvaluateFrameMotion(gt, est, 0.5, 0.02);
  ASSERT_EQ(errors.size(), 3u);
  EXPECT_NEAR(errors[0].timestamp, 0.1, kTolerance);
  EXPECT_NEAR(errors[0].translation_direction_error_deg, 90.0, kTolerance);
  EXPECT_NEAR(errors[0].translation_ratio, 0.5, kTolerance);
  EXPECT_NEAR(errors[1].timestamp, 0.3, kTolerance);
  EXPECT_NEAR(errors[1].translation_direction_error_deg, 90.0, kTolerance);
  // gt stands still from 0.3 to 0.4 and so does est: neither a direction nor a ratio.
  EXPECT_TRUE(std::isnan(errors[2].translation_direction_error_deg));
  EXPECT_TRUE(std::isnan(errors[2].translation_ratio));
  EXPECT_NEAR(errors[2].rotation_error_deg, 0.0, kTolerance);

  std::ostringstream csv;
  WriteFrameMotionErrorsCsv(errors, csv);
  EXPECT_EQ(csv.str().substr(0, csv.str().find('\n')),
            "timestamp,rotation_error_deg,translation_direction_error_deg,translation_ratio,"
            "true_rotation_deg,rotation_along_true_deg");
  EXPECT_NE(csv.str().find("0.4,0,nan,nan,0,0\n"), std::string::npos) << csv.str();
  // Nothing turns: no rotation ratio.
  EXPECT_TRUE(std::isnan(PooledRotationRatio(errors)));
}

TEST(EvaluateFrameMotion, TheRotationRatioIsTheTrackedShareOfTheTrueTurns) {
  // gt turns 3 deg per frame about an axis tilted from z; est turns 3.3 deg per frame about the
  // same axis (10% over-rotated) plus 0.5 deg per frame about a perpendicular axis, which adds to
  // the rotation error but not to the rotation along the true axis.
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const Eigen::Vector3d across = axis.cross(Eigen::Vector3d::UnitX()).normalized();
  const double deg = M_PI / 180.0;
  Trajectory gt, est;
  Eigen::Quaterniond q_gt = Eigen::Quaterniond::Identity(), q_est = q_gt;
  for (int i = 0; i < 6; ++i) {
    gt.push_back(Pose(0.1 * i, Eigen::Vector3d(0.1 * i, 0, 0), q_gt));
    est.push_back(Pose(0.1 * i, Eigen::Vector3d(0.1 * i, 0, 0), q_est));
    q_gt = q_gt * Eigen::AngleAxisd(3.0 * deg, axis);
    // Rotation vector 3.3 deg along the axis and 0.5 deg across it.
    const Eigen::Vector3d step = (3.3 * axis + 0.5 * across) * deg;
    q_est = q_est * Eigen::AngleAxisd(step.norm(), step.normalized());
  }
  const std::vector<FrameMotionError> errors = EvaluateFrameMotion(gt, est, 1.0, 0.02);
  ASSERT_EQ(errors.size(), 5u);
  for (const FrameMotionError& error : errors) {
    EXPECT_NEAR(error.true_rotation_deg, 3.0, 1e-9);
    EXPECT_NEAR(error.rotation_along_true_deg, 3.3, 1e-9);
  }
  EXPECT_NEAR(PooledRotationRatio(errors), 1.1, 1e-9);
}

TEST(EvaluateFrameMotion, InterpolatesTheGroundTruthAtTheEstimateTimestamps) {
  // 100 Hz ground truth of a camera moving at 1 m/s along x and turning at 60 deg/s about z; a
  // 30 Hz estimate equal to the true pose at its timestamps. Between the two ground-truth poses
  // around a frame the motion is linear in position and a rotation about one axis at a constant
  // rate: the interpolation is exact, every error 0. The nearest pose (up to 5 ms off) would read
  // up to 0.3 deg of rotation error.
  const double rate = 60.0 * M_PI / 180.0;
  const auto truth = [rate](double t) {
    return Pose(t, Eigen::Vector3d(t, 0, 0),
                Eigen::Quaterniond(Eigen::AngleAxisd(rate * t, Eigen::Vector3d::UnitZ())));
  };
  Trajectory gt, est;
  for (int k = 0; k <= 100; ++k) gt.push_back(truth(0.01 * k));
  for (int i = 0; i < 30; ++i) est.push_back(truth(i / 30.0));
  const std::vector<FrameMotionError> errors = EvaluateFrameMotion(gt, est, 1.0, 0.02);
  ASSERT_EQ(errors.size(), 29u);
  for (const FrameMotionError& error : errors) {
    EXPECT_NEAR(error.rotation_error_deg, 0.0, 1e-6) << error.timestamp;
    EXPECT_NEAR(error.translation_direction_error_deg, 0.0, 1e-6) << error.timestamp;
    EXPECT_NEAR(error.translation_ratio, 1.0, 1e-9) << error.timestamp;
  }
}

TEST(EvaluateFrameMotion, RejectsABadScale) {
  const Trajectory trajectory = CurvedTrajectory(5);
  EXPECT_THROW(EvaluateFrameMotion(trajectory, trajectory, 0.0, 0.02), std::invalid_argument);
  EXPECT_THROW(EvaluateFrameMotion(trajectory, trajectory, std::nan(""), 0.02),
               std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
