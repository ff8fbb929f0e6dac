// The corners' epipolar error against a start's motion (corner_epipolar_error.h), on corners
// projected from known points along known poses.
#include "backend/odometry/corner_epipolar_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

namespace pldvo {
namespace {

PinholeCamera Camera() { return PinholeCamera{640, 480, 525.0, 525.0, 319.5, 239.5}; }

// A camera moving sideways and forward while it turns about the vertical axis: world_from_cam of
// frames 0..num_frames-1.
std::vector<SE3> Motion(int num_frames, const Eigen::Vector3d& step) {
  std::vector<SE3> poses;
  for (int k = 0; k < num_frames; ++k) {
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(0.004 * k, Eigen::Vector3d::UnitY()).toRotationMatrix();
    poses.emplace_back(rotation, step * k);
  }
  return poses;
}

// Points 2-6 m in front of frame 0 projected into every frame, with Gaussian pixel noise; a
// corner's track ends at the first frame it leaves the image (or at lose_after).
CornerTracks Project(const std::vector<SE3>& world_from_cam, double noise_px, int num_corners,
                     int lose_after = 1 << 30) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  const PinholeCamera camera = Camera();
  CornerTracks tracks;
  for (int i = 0; i < num_corners; ++i) {
    const double depth = 2.0 + 4.0 * u(rng);
    const double column = u(rng) * camera.width, row = u(rng) * camera.height;
    const Eigen::Vector3d in_cam0 = depth * camera.Unproject(Eigen::Vector2d(column, row));
    const Eigen::Vector3d world = world_from_cam[0] * in_cam0;
    std::vector<cv::Point2f> track;
    for (size_t k = 0; k < world_from_cam.size() && static_cast<int>(k) <= lose_after; ++k) {
      const Eigen::Vector3d p = world_from_cam[k].Inverse() * world;
      if (p.z() <= 0.0) break;
      const Eigen::Vector2d pixel = camera.Project(p);
      const double x = pixel.x() + noise(rng), y = pixel.y() + noise(rng);
      if (x < 0.0 || y < 0.0 || x > camera.width || y > camera.height) break;
      track.emplace_back(static_cast<float>(x), static_cast<float>(y));
    }
    tracks.positions.push_back(track);
  }
  return tracks;
}

// The same camera centres seen from frame 0 with their direction turned by angle_deg about the
// vertical axis of frame 0 (a wrong start's motion; the rotations stay right).
std::vector<SE3> TurnDirection(const std::vector<SE3>& world_from_cam, double angle_deg) {
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(angle_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  std::vector<SE3> turned;
  for (const SE3& pose : world_from_cam) {
    const SE3 cam0_from_cam = world_from_cam[0].Inverse() * pose;
    turned.push_back(world_from_cam[0] *
                     SE3(cam0_from_cam.rotation(), turn * cam0_from_cam.translation()));
  }
  return turned;
}

TEST(CornerEpipolarErrorTest, TheTrueMotionFitsNoiselessCorners) {
  const std::vector<SE3> poses = Motion(30, Eigen::Vector3d(0.01, 0.0, 0.005));
  const CornerTracks tracks = Project(poses, 0.0, 200);
  EXPECT_LT(CornerEpipolarErrorPx(tracks, poses, Camera()), 1e-3);
}

TEST(CornerEpipolarErrorTest, AWrongDirectionFitsWorseThanTheNoise) {
  // With 0.5 px of noise the true motion's median Sampson distance is about 0.67 x 0.5 px (the
  // median of |N(0, 0.5)|); a direction 20 deg off (the texture-less rooms' wrong starts) adds a
  // systematic error that grows with the baseline.
  const std::vector<SE3> poses = Motion(60, Eigen::Vector3d(0.01, 0.0, 0.005));
  const CornerTracks tracks = Project(poses, 0.5, 300);
  const double truth = CornerEpipolarErrorPx(tracks, poses, Camera());
  const double wrong = CornerEpipolarErrorPx(tracks, TurnDirection(poses, 20.0), Camera());
  const double slightly = CornerEpipolarErrorPx(tracks, TurnDirection(poses, 2.0), Camera());
  std::printf("epipolar error px: truth %.3f, 2 deg off %.3f, 20 deg off %.3f\n", truth, slightly,
              wrong);
  EXPECT_NEAR(truth, 0.6745 * 0.5, 0.05);
  EXPECT_GT(wrong, 3.0 * truth);
  EXPECT_GT(slightly, truth);
  EXPECT_LT(slightly, wrong);
}

TEST(CornerEpipolarErrorTest, TracksThatDriftOffEveryMotionDoNotCount) {
  // A texture-less room's weak corners: by frame 40 about half fit no motion. Here 45% of the
  // tracks drift by a random walk of 0.4 px per frame; the median over all tracks would sit among
  // them, the consensus leaves the truth at the noise level and a wrong direction above it.
  const std::vector<SE3> poses = Motion(60, Eigen::Vector3d(0.01, 0.0, 0.005));
  CornerTracks tracks = Project(poses, 0.5, 400);
  std::mt19937 rng(11);
  std::normal_distribution<float> step(0.0f, 0.4f);
  for (size_t i = 0; i < tracks.positions.size(); i += 2) {
    if (i % 20 == 18) continue;  // 9 in 20 drift
    cv::Point2f drift(0.0f, 0.0f);
    for (size_t k = 1; k < tracks.positions[i].size(); ++k) {
      drift += cv::Point2f(step(rng), step(rng));
      tracks.positions[i][k] += drift;
    }
  }
  const double truth = CornerEpipolarErrorPx(tracks, poses, Camera());
  const double wrong = CornerEpipolarErrorPx(tracks, TurnDirection(poses, 20.0), Camera());
  std::printf("with drifting tracks: truth %.3f, 20 deg off %.3f px\n", truth, wrong);
  EXPECT_LT(truth, 0.45);
  EXPECT_GT(wrong, 3.0 * truth);
}

TEST(CornerEpipolarErrorTest, DoesNotDependOnTheScale) {
  const std::vector<SE3> poses = Motion(30, Eigen::Vector3d(0.01, 0.002, 0.005));
  const CornerTracks tracks = Project(poses, 0.5, 200);
  std::vector<SE3> scaled;
  for (const SE3& pose : poses) scaled.emplace_back(pose.rotation(), 3.0 * pose.translation());
  EXPECT_NEAR(CornerEpipolarErrorPx(tracks, scaled, Camera()),
              CornerEpipolarErrorPx(tracks, poses, Camera()), 1e-9);
}

TEST(CornerEpipolarErrorTest, FramesWithoutEnoughCornersOrMotionDoNotCount) {
  const std::vector<SE3> poses = Motion(30, Eigen::Vector3d(0.01, 0.0, 0.005));
  // Tracks lost after frame 10: frames 11.. have no corner and do not count; frames 1-10 alone
  // give the same error as the first 11 poses.
  const CornerTracks short_tracks = Project(poses, 0.5, 200, /*lose_after=*/10);
  const std::vector<SE3> first(poses.begin(), poses.begin() + 11);
  EXPECT_DOUBLE_EQ(CornerEpipolarErrorPx(short_tracks, poses, Camera()),
                   CornerEpipolarErrorPx(short_tracks, first, Camera()));
  // Fewer corners than kMinEpipolarCorners, or no translation at all: no frame counts.
  EXPECT_TRUE(std::isnan(
      CornerEpipolarErrorPx(Project(poses, 0.5, kMinEpipolarCorners - 1), poses, Camera())));
  const std::vector<SE3> turning_in_place = Motion(30, Eigen::Vector3d::Zero());
  EXPECT_TRUE(std::isnan(
      CornerEpipolarErrorPx(Project(turning_in_place, 0.5, 200), turning_in_place, Camera())));
  EXPECT_TRUE(std::isnan(CornerEpipolarErrorPx(short_tracks, {}, Camera())));
}

TEST(CornerEpipolarErrorTest, ReanchoredTracksCheckTheFramesAfterFrameZerosCornersAreLost) {
  // Frame 0's corners are lost after frame 20 and corners detected in frame 20 take over. A start
  // that follows the truth to frame 20 and then moves 20 deg off its direction fits frame 0's
  // corners exactly as the truth does; frame 20's corners tell them apart.
  constexpr int kAnchor = 20;
  const std::vector<SE3> poses = Motion(60, Eigen::Vector3d(0.01, 0.0, 0.005));
  const std::vector<SE3> later(poses.begin() + kAnchor, poses.end());
  std::vector<SE3> wrong(poses.begin(), poses.begin() + kAnchor);
  for (const SE3& pose : TurnDirection(later, 20.0)) wrong.push_back(pose);

  CornerTracks tracks = Project(poses, 0.5, 300, /*lose_after=*/kAnchor);
  const double frame_0_truth = CornerEpipolarErrorPx(tracks, poses, Camera());
  EXPECT_DOUBLE_EQ(CornerEpipolarErrorPx(tracks, wrong, Camera()), frame_0_truth);

  tracks.anchors.assign(tracks.positions.size(), 0);
  const CornerTracks from_anchor = Project(later, 0.5, 300);
  for (const std::vector<cv::Point2f>& track : from_anchor.positions) {
    tracks.positions.push_back(track);
    tracks.anchors.push_back(kAnchor);
  }
  const double truth = CornerEpipolarErrorPx(tracks, poses, Camera());
  const double off = CornerEpipolarErrorPx(tracks, wrong, Camera());
  std::printf("re-anchored at frame %d: truth %.3f px, 20 deg off after it %.3f px\n", kAnchor,
              truth, off);
  EXPECT_NEAR(truth, 0.6745 * 0.5, 0.05);
  EXPECT_GT(off, 3.0 * truth);
  // The anchor's frames are measured from the anchor: the truth shifted by any pose before it
  // (here the first 20 frames replaced by the identity) fits them alike.
  std::vector<SE3> other_start(kAnchor, SE3());
  other_start.insert(other_start.end(), later.begin(), later.end());
  CornerTracks anchor_only = from_anchor;
  anchor_only.anchors.assign(anchor_only.positions.size(), kAnchor);
  EXPECT_NEAR(CornerEpipolarErrorPx(anchor_only, other_start, Camera()),
              CornerEpipolarErrorPx(anchor_only, poses, Camera()), 1e-9);
}

}  // namespace
}  // namespace pldvo
