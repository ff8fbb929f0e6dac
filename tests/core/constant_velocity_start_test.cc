#include "core/constant_velocity_start.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace pldvo {
namespace {

constexpr double kTolerance = 1e-4;  // EvaluationOptions' default
constexpr int kMinSteps = 5;

StampedPose Pose(double t, const Eigen::Vector3d& position, double yaw = 0.0) {
  StampedPose pose;
  pose.timestamp = t;
  pose.world_from_cam =
      SE3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())), position);
  return pose;
}

// KITTI 00's start in miniature: `constant` poses at 8.3 m/s along one direction, frame times
// alternating 0.1036 / 0.1037 s, the camera turning 0.14 deg per frame; then the car accelerates
// by 1% per frame and steers (the measured part).
Trajectory ExtrapolatedStart(int constant, int total) {
  const Eigen::Vector3d velocity(-0.45, -0.27, 8.28);
  Trajectory trajectory;
  double t = 0.0, yaw = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = velocity;
  for (int i = 0; i < total; ++i) {
    trajectory.push_back(Pose(t, position, yaw));
    const double dt = i % 2 == 0 ? 0.1036 : 0.1037;
    if (i + 1 >= constant) {
      v = 1.01 * (Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()) * v);
    }
    position += v * dt;
    t += dt;
    yaw += 0.0024;
  }
  return trajectory;
}

TEST(ConstantVelocityStartTest, FindsTheExtrapolatedPosesAtTheStart) {
  EXPECT_EQ(ConstantVelocityStartPoses(ExtrapolatedStart(15, 40), kTolerance, kMinSteps), 15);
  EXPECT_EQ(ConstantVelocityStartPoses(ExtrapolatedStart(7, 40), kTolerance, kMinSteps), 7);
}

TEST(ConstantVelocityStartTest, FewerStepsThanTheMinimumAreNoStart) {
  // 4 steps of one velocity: a measured path can repeat its velocity that often by chance.
  EXPECT_EQ(ConstantVelocityStartPoses(ExtrapolatedStart(5, 40), kTolerance, kMinSteps), 0);
  EXPECT_EQ(ConstantVelocityStartPoses(ExtrapolatedStart(5, 40), kTolerance, 4), 5);
}

TEST(ConstantVelocityStartTest, MeasuredMotionHasNone) {
  // The same constant-velocity start measured: 0.1 mm of position noise per pose (better than any
  // GPS/INS) changes consecutive velocities by ~2.4 mm/s, 3e-4 of the speed.
  Trajectory measured = ExtrapolatedStart(15, 40);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 1e-4);
  for (StampedPose& pose : measured) {
    const Eigen::Vector3d p =
        pose.world_from_cam.translation() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    pose.world_from_cam = SE3(pose.world_from_cam.rotation(), p);
  }
  EXPECT_EQ(ConstantVelocityStartPoses(measured, kTolerance, kMinSteps), 0);
  // A smooth curve at 30 Hz (the renders' paths are sums of sinusoids).
  Trajectory curve;
  for (int i = 0; i < 60; ++i) {
    const double t = i / 30.0;
    curve.push_back(Pose(t, Eigen::Vector3d(std::sin(0.7 * t), 0.1 * std::cos(1.3 * t), 0.25 * t)));
  }
  EXPECT_EQ(ConstantVelocityStartPoses(curve, kTolerance, kMinSteps), 0);
}

TEST(ConstantVelocityStartTest, AWholeConstantPathIsOneStart) {
  EXPECT_EQ(ConstantVelocityStartPoses(ExtrapolatedStart(40, 40), kTolerance, kMinSteps), 40);
}

TEST(ConstantVelocityStartTest, ACameraAtRestIsNoStart) {
  Trajectory resting;
  for (int i = 0; i < 20; ++i) resting.push_back(Pose(0.1 * i, Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(ConstantVelocityStartPoses(resting, kTolerance, kMinSteps), 0);
  EXPECT_EQ(ConstantVelocityStartPoses({}, kTolerance, kMinSteps), 0);
  EXPECT_EQ(ConstantVelocityStartPoses({resting[0]}, kTolerance, kMinSteps), 0);
}

TEST(ConstantVelocityStartTest, BadArgumentsThrow) {
  const Trajectory start = ExtrapolatedStart(15, 40);
  EXPECT_THROW(ConstantVelocityStartPoses(start, -1e-3, kMinSteps), std::invalid_argument);
  EXPECT_THROW(ConstantVelocityStartPoses(start, std::nan(""), kMinSteps), std::invalid_argument);
  EXPECT_THROW(ConstantVelocityStartPoses(start, kTolerance, 0), std::invalid_argument);
  Trajectory repeated = start;
  repeated[3].timestamp = repeated[2].timestamp;
  EXPECT_THROW(ConstantVelocityStartPoses(repeated, kTolerance, kMinSteps), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
