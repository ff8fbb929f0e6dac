// The two-view bootstrap (backend/odometry/two_view_bootstrap.h) on a small rendered textured
// sequence (320x240, 36 frames) against its ground truth: the second view's pose and frame 0's map;
// and its errors when the camera does not move, turns with too little translation or the image
// has no corners.
#include "backend/odometry/two_view_bootstrap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/odometry/odometry_config.h"
#include "core/dataset.h"
#include "core/evaluation.h"
#include "core/statistics.h"
#include "experiments/synthetic/synthetic_sequence.h"
#include "tests/render_cache.h"
#include "tests/small_lowtex_options.h"

namespace pldvo {
namespace {

constexpr int kFrames = 36;

// Rendered frames held in memory as a Dataset (frame_of[i] is the rendered frame shown as i).
class RenderedDataset : public Dataset {
 public:
  RenderedDataset(const synthetic::SyntheticSequence& sequence, std::vector<cv::Mat> images,
                  std::vector<int> frame_of)
      : sequence_(sequence), images_(std::move(images)), frame_of_(std::move(frame_of)) {}
  std::string format() const override { return "rendered"; }
  int size() const override { return static_cast<int>(frame_of_.size()); }
  double timestamp(int i) const override { return i / 30.0; }
  Frame Load(int i) const override {
    Frame frame;
    frame.index = i;
    frame.timestamp = timestamp(i);
    frame.image = images_.at(frame_of_.at(i));
    return frame;
  }
  const PinholeCamera& camera() const override { return sequence_.camera; }
  const Trajectory* ground_truth() const override { return &sequence_.ground_truth; }

 private:
  const synthetic::SyntheticSequence& sequence_;
  std::vector<cv::Mat> images_;
  std::vector<int> frame_of_;
};

struct TexturedSequence {
  synthetic::SyntheticSequence sequence;
  std::vector<cv::Mat> images;  // CV_32F, the first `frames` rendered
  cv::Mat first_depth;
};

// The textured preset, seed 2, at the size of the small test sequence; renders `frames` frames.
TexturedSequence Textured(int frames) {
  synthetic::SynthOptions options = test::SmallLowtexOptions(kFrames);
  options.preset = "textured";
  options.seed = 2;
  TexturedSequence result;
  result.sequence = synthetic::MakeSequence(options);
  for (int i = 0; i < frames; ++i) {
    const synthetic::RenderedFrame frame = test::RenderFrameForTest(result.sequence, i);
    cv::Mat image;
    frame.image.convertTo(image, CV_32F);
    result.images.push_back(image);
    if (i == 0) result.first_depth = frame.depth;
  }
  return result;
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// The rotation-free parallax on known geometry: pixels of points at depths 2 and 4 m seen from two
// cameras.
class RotationFreeParallaxTest : public ::testing::Test {
 protected:
  const cv::Matx33d K{262.5, 0.0, 159.5, 0.0, 262.5, 119.5, 0.0, 0.0, 1.0};

  // Points in frame 0 inside the middle third of the image (a 21 deg field of view), alternately at
  // depth 2 and 4.
  std::vector<Eigen::Vector3d> Points() const {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 200; ++i) {
      const double depth = i % 2 == 0 ? 2.0 : 4.0;
      const double u = 107.0 + (i * 37 % 107), v = 80.0 + (i * 53 % 80);
      points.emplace_back((u - K(0, 2)) / K(0, 0) * depth, (v - K(1, 2)) / K(1, 1) * depth, depth);
    }
    return points;
  }
  std::vector<cv::Point2f> Project(const std::vector<Eigen::Vector3d>& points,
                                   const Eigen::Matrix3d& rotation,
                                   const Eigen::Vector3d& translation) const {
    std::vector<cv::Point2f> pixels;
    for (const Eigen::Vector3d& X : points) {
      const Eigen::Vector3d p = rotation * X + translation;
      pixels.emplace_back(K(0, 0) * p.x() / p.z() + K(0, 2), K(1, 1) * p.y() / p.z() + K(1, 2));
    }
    return pixels;
  }
};

// Float pixels carry about 3e-5 px of rounding at these coordinates; 1e-3 px is far above it and
// far below any parallax the gate compares with.
TEST_F(RotationFreeParallaxTest, PureRotationHasNone) {
  const std::vector<Eigen::Vector3d> points = Points();
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.1, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
  const std::vector<cv::Point2f> x0 = Project(points, Eigen::Matrix3d::Identity(), {0, 0, 0});
  EXPECT_LT(RotationFreeParallaxPx(x0, Project(points, turn, {0, 0, 0}), K), 1e-3);
}

// A sideways translation t moves the near points by f t / 2 and the far ones by f t / 4; the best
// rotation takes the mean, leaving f t / 8 (1.3125 px for t = 4 cm) to every point, up to the
// field of view's curvature (the tolerance). Turning the second camera adds nothing.
TEST_F(RotationFreeParallaxTest, SidewaysTranslationLeavesTheDepthDifference) {
  const std::vector<Eigen::Vector3d> points = Points();
  const Eigen::Vector3d t(0.04, 0.0, 0.0);
  const std::vector<cv::Point2f> x0 = Project(points, Eigen::Matrix3d::Identity(), {0, 0, 0});
  const double moved =
      RotationFreeParallaxPx(x0, Project(points, Eigen::Matrix3d::Identity(), t), K);
  EXPECT_NEAR(moved, 262.5 * 0.04 / 8.0, 0.05);
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d(1.0, -0.4, 0.5).normalized()).toRotationMatrix();
  EXPECT_NEAR(RotationFreeParallaxPx(x0, Project(points, turn, turn * t), K), moved, 1e-3);
  EXPECT_THROW(RotationFreeParallaxPx(x0, {}, K), std::invalid_argument);
}

// A bootstrap's second view and frame 0's map against the ground truth.
struct BootstrapErrors {
  double rotation_deg = 0.0;
  double direction_deg = 0.0;  // of the second view's translation
  double map = 0.0;            // median relative depth error after a median scale alignment
  double pose_over_map_scale = 0.0;
  size_t map_points = 0;  // with ground truth
};

BootstrapErrors Evaluate(const TwoViewBootstrap& result, const Dataset& dataset,
                         const cv::Mat& gt_depth) {
  BootstrapErrors errors;
  const Trajectory& gt = *dataset.ground_truth();
  const SE3 true_second_from_first =
      gt[result.second_view].world_from_cam.Inverse() * gt[0].world_from_cam;
  errors.rotation_deg = Eigen::AngleAxisd(true_second_from_first.rotation().inverse() *
                                          result.second_from_first.rotation())
                            .angle() *
                        180.0 / M_PI;
  errors.direction_deg =
      AngleDeg(result.second_from_first.translation(), true_second_from_first.translation());
  std::vector<double> ratios;
  for (int y = 0; y < gt_depth.rows; ++y) {
    for (int x = 0; x < gt_depth.cols; ++x) {
      const float z = result.depth.at<float>(y, x);
      if (z > 0.f && gt_depth.at<float>(y, x) > 0.f) ratios.push_back(gt_depth.at<float>(y, x) / z);
    }
  }
  errors.map_points = ratios.size();
  if (ratios.empty()) return errors;
  const double scale = Median(ratios);
  std::vector<double> relative;
  for (double ratio : ratios) relative.push_back(std::abs(ratio / scale - 1.0));
  errors.map = Median(relative);
  errors.pose_over_map_scale = true_second_from_first.translation().norm() /
                               result.second_from_first.translation().norm() / scale;
  return errors;
}

void Print(const char* what, const TwoViewBootstrap& result, const BootstrapErrors& errors) {
  std::printf(
      "%s: second view %d, %d of %d corners, parallax %.2f deg (rotation-free %.2f px), "
      "direction std %.2f deg, %d points refined photometrically; rotation error %.3f deg, "
      "direction error %.2f deg, map: %d points, median rel. error %.4f, pose scale / map "
      "scale %.3f\n",
      what, result.second_view, result.inliers, result.tracks, result.parallax_deg,
      result.rotation_free_parallax_px, result.direction_std_deg, result.photometric_points,
      errors.rotation_deg, errors.direction_deg, result.points, errors.map,
      errors.pose_over_map_scale);
}

// The corners alone (no photometric pass) and the default start (one pass) on the same frames.
TEST(TwoViewBootstrapTest, RecoversTheSecondViewAndFrameZerosMap) {
  const TexturedSequence textured = Textured(kFrames);
  std::vector<int> frames;
  for (int i = 0; i < kFrames; ++i) frames.push_back(i);
  const RenderedDataset dataset(textured.sequence, textured.images, frames);
  OdometryConfig corners_only;
  corners_only.odometry.two_view_photometric_passes = 0;
  const TwoViewBootstrap from_corners = BootstrapFromTwoViews(dataset, corners_only, kFrames);
  const OdometryConfig config;
  const TwoViewBootstrap result = BootstrapFromTwoViews(dataset, config, kFrames);
  ASSERT_GT(result.second_view, 0);
  ASSERT_EQ(result.second_view, from_corners.second_view);  // the refinement comes after
  EXPECT_GE(result.inliers, config.odometry.two_view_min_inliers);
  EXPECT_GE(result.parallax_deg, config.odometry.two_view_min_parallax_deg);
  EXPECT_GE(result.rotation_free_parallax_px,
            config.odometry.two_view_min_rotation_free_parallax_px);
  EXPECT_EQ(from_corners.photometric_points, 0);
  EXPECT_GT(result.photometric_points, 500);

  const BootstrapErrors before = Evaluate(from_corners, dataset, textured.first_depth);
  const BootstrapErrors after = Evaluate(result, dataset, textured.first_depth);
  Print("corners", from_corners, before);
  Print("photometric", result, after);
  ASSERT_GT(after.map_points, 1000u);
  // The corners' direction within three of its standard deviations, the rotation within 0.5 deg
  // (a direction error of a few degrees moves the rotation by a fraction of one).
  EXPECT_LE(from_corners.direction_std_deg, config.odometry.two_view_max_direction_std_deg);
  EXPECT_LT(before.direction_deg, 3.0 * from_corners.direction_std_deg);
  EXPECT_LT(before.rotation_deg, 0.5);
  // The photometric pass takes this render's direction error from 2.53 to 0.84 deg, the rotation's
  // from 0.38 to 0.13 deg and the map's from 1.4% to 0.6%: it must at least halve the direction
  // error, to within 1.2 deg.
  EXPECT_LT(after.direction_deg, 0.5 * before.direction_deg);
  EXPECT_LT(after.direction_deg, 1.2);
  EXPECT_LT(after.rotation_deg, 0.2);
  EXPECT_LT(after.map, 0.01);
  EXPECT_NEAR(after.pose_over_map_scale, 1.0, 0.03);
}

// Frame 0's stereo from the corners' median inverse depth gives the same map whatever
// mapping.init_seed; from the random map it does not. Both fit the ground truth alike.
TEST(TwoViewBootstrapTest, TheCornersPriorDoesNotDependOnTheSeed) {
  const TexturedSequence textured = Textured(kFrames);
  std::vector<int> frames;
  for (int i = 0; i < kFrames; ++i) frames.push_back(i);
  const RenderedDataset dataset(textured.sequence, textured.images, frames);
  auto bootstrap = [&](OdometryOptions::TwoViewMapPrior prior, int seed) {
    OdometryConfig config;
    config.odometry.two_view_map_prior = prior;
    config.mapping.init_seed = seed;
    return BootstrapFromTwoViews(dataset, config, kFrames);
  };
  const auto kRandom = OdometryOptions::TwoViewMapPrior::kRandom;
#ifdef PLDVO_SANITIZE
  // Under the sanitizers (docs/reliability.md, "CI") the random prior's code once, one bootstrap
  // instead of four: the corners' prior runs in RecoversTheSecondViewAndFrameZerosMap, the
  // comparisons over seeds in the Release suite.
  EXPECT_LT(Evaluate(bootstrap(kRandom, 1), dataset, textured.first_depth).map, 0.01);
  return;
#endif
  const auto kCornerMedian = OdometryOptions::TwoViewMapPrior::kCornerMedian;
  const TwoViewBootstrap corners_1 = bootstrap(kCornerMedian, 1),
                         corners_7 = bootstrap(kCornerMedian, 7);
  const TwoViewBootstrap random_1 = bootstrap(kRandom, 1), random_7 = bootstrap(kRandom, 7);
  auto differing = [](const cv::Mat& a, const cv::Mat& b) { return cv::countNonZero(a != b); };
  EXPECT_EQ(differing(corners_1.depth, corners_7.depth), 0);
  EXPECT_GT(differing(random_1.depth, random_7.depth), 0);
  const BootstrapErrors from_corners = Evaluate(corners_1, dataset, textured.first_depth);
  const BootstrapErrors from_random = Evaluate(random_1, dataset, textured.first_depth);
  Print("corners' median prior", corners_1, from_corners);
  Print("random prior", random_1, from_random);
  ASSERT_GT(from_corners.map_points, 1000u);
  EXPECT_LT(from_corners.map, 0.01);
  EXPECT_LT(from_random.map, 0.01);
}

TEST(TwoViewBootstrapTest, StaticCameraHasNoParallax) {
  const TexturedSequence textured = Textured(1);
  const RenderedDataset dataset(textured.sequence, textured.images, std::vector<int>(kFrames, 0));
  try {
    BootstrapFromTwoViews(dataset, OdometryConfig(), kFrames);
    FAIL() << "a static camera must not bootstrap";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("parallax"), std::string::npos) << e.what();
  }
}

// The small lowtex sequence's first `count` frames (CV_32F): the camera turns with little
// translation there (the near-rotation start below).
std::vector<cv::Mat> NearRotationFrames(const synthetic::SyntheticSequence& sequence, int count) {
  std::vector<cv::Mat> images;
  for (int i = 0; i < count; ++i) {
    cv::Mat image;
    test::RenderFrameForTest(sequence, i).image.convertTo(image, CV_32F);
    images.push_back(image);
  }
  return images;
}

// What BootstrapFromTwoViews throws over `num_frames` frames, or "accepted".
std::string Outcome(const Dataset& dataset, const OdometryConfig& config, int num_frames,
                    CornerTracks* unsettled_tracks = nullptr) {
  try {
    BootstrapFromTwoViews(dataset, config, num_frames, unsettled_tracks);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "accepted";
}

// The start of the lowtex preset at 320x240 (seed 1, 150-frame path): the camera turns 4.3 deg
// and moves 1.9 cm in the first 6 frames, so the corners' motion is nearly all rotation (0.6 px
// rotation-free at frame 6). With the strongest corners only (quality 0.01, 7 px apart) the
// essential matrix of that noise decomposes into a motion whose triangulated parallax passes the
// 2 deg gate with a translation 45 deg off the truth; this map made every run from it fail
// (docs/bootstrap.md). Either gate rejects it on its own: the rotation-free parallax, and the
// direction's uncertainty after the bundle adjustment.
TEST(TwoViewBootstrapTest, NearRotationIsRejectedByEitherGate) {
  constexpr int kLowtexFrames = 12;
  const synthetic::SynthOptions options = test::SmallLowtexOptions(150);
  const synthetic::SyntheticSequence sequence = synthetic::MakeSequence(options);
  std::vector<int> frames(kLowtexFrames);
  std::iota(frames.begin(), frames.end(), 0);
  const RenderedDataset dataset(sequence, NearRotationFrames(sequence, kLowtexFrames), frames);
  OdometryConfig strong_corners;
  strong_corners.odometry.two_view_corner_quality = 0.01;
  strong_corners.odometry.two_view_corner_min_distance_px = 7.0;
  const auto rejection = [&](const OdometryConfig& config) {
    return Outcome(dataset, config, kLowtexFrames);
  };

  OdometryConfig unguarded = strong_corners;
  unguarded.odometry.two_view_min_rotation_free_parallax_px = 0.0;
  unguarded.odometry.two_view_max_direction_std_deg = 180.0;
  unguarded.odometry.two_view_stable_frames = 1;
  const TwoViewBootstrap wrong = BootstrapFromTwoViews(dataset, unguarded, kLowtexFrames);
  const Trajectory& gt = *dataset.ground_truth();
  const SE3 true_second_from_first =
      gt[wrong.second_view].world_from_cam.Inverse() * gt[0].world_from_cam;
  const double direction_error_deg =
      AngleDeg(wrong.second_from_first.translation(), true_second_from_first.translation());
  std::printf(
      "without the gates: second view %d, parallax %.2f deg, rotation-free %.3f px, "
      "direction std %.1f deg, direction error %.1f deg\n",
      wrong.second_view, wrong.parallax_deg, wrong.rotation_free_parallax_px,
      wrong.direction_std_deg, direction_error_deg);
  EXPECT_GT(direction_error_deg, 20.0);
  EXPECT_LT(wrong.rotation_free_parallax_px,
            OdometryConfig().odometry.two_view_min_rotation_free_parallax_px);
  EXPECT_GT(wrong.direction_std_deg, OdometryConfig().odometry.two_view_max_direction_std_deg);

  OdometryConfig rotation_free_gate = unguarded;
  rotation_free_gate.odometry.two_view_min_rotation_free_parallax_px =
      OdometryConfig().odometry.two_view_min_rotation_free_parallax_px;
  const std::string by_parallax = rejection(rotation_free_gate);
  EXPECT_NE(by_parallax.find("no frame up to"), std::string::npos) << by_parallax;
  // Corners that pass no parallax gate tell nothing of the direction: none handed out.
  CornerTracks no_tracks;
  EXPECT_THROW(BootstrapFromTwoViews(dataset, rotation_free_gate, kLowtexFrames, &no_tracks),
               std::runtime_error);
  EXPECT_TRUE(no_tracks.positions.empty());

  OdometryConfig direction_gate = strong_corners;
  direction_gate.odometry.two_view_min_rotation_free_parallax_px = 0.0;
  const std::string by_direction = rejection(direction_gate);
  EXPECT_NE(by_direction.find("fixes the translation direction"), std::string::npos)
      << by_direction;
  // The failure says where the parallax gates were first passed (the unguarded start's second
  // view) and that no corner was lost: a re-anchored start may begin there.
  try {
    BootstrapFromTwoViews(dataset, direction_gate, kLowtexFrames);
    ADD_FAILURE() << "the direction gate passed";
  } catch (const TwoViewBootstrapFailure& failure) {
    EXPECT_EQ(failure.tracks_lost_at, -1);
    EXPECT_EQ(failure.first_gated, wrong.second_view);
    EXPECT_EQ(TwoViewRestartFrame(failure, true), wrong.second_view);
    EXPECT_EQ(TwoViewRestartFrame(failure, false), -1);
  }
  // Failed at the direction gate: every corner's track for the random start's choice, those
  // alive to the last frame at least two_view_min_inliers, each from frame 0 on.
  CornerTracks unsettled;
  EXPECT_THROW(BootstrapFromTwoViews(dataset, direction_gate, kLowtexFrames, &unsettled),
               std::runtime_error);
  int alive = 0;
  for (const std::vector<cv::Point2f>& track : unsettled.positions) {
    ASSERT_FALSE(track.empty());
    ASSERT_LE(track.size(), static_cast<size_t>(kLowtexFrames));
    alive += track.size() == static_cast<size_t>(kLowtexFrames);
  }
  EXPECT_GE(alive, direction_gate.odometry.two_view_min_inliers);
  // The ground-truth motion fits them to the tracking's accuracy.
  std::vector<SE3> truth;
  for (int k = 0; k < kLowtexFrames; ++k) truth.push_back(gt[k].world_from_cam);
  const double truth_px = CornerEpipolarErrorPx(unsettled, truth, dataset.camera());
  std::printf("tracked corners' epipolar error against the ground truth: %.3f px\n", truth_px);
  EXPECT_LT(truth_px, 0.5);
}

// Where a chain of two-view starts begins again: where the corners were lost (the next frame when
// the anchor itself has too few), else after a failed direction gate at the first frame that
// passed the parallax gates, if asked; nowhere when no frame passed them.
TEST(TwoViewBootstrapTest, RestartFrameFollowsTheFailure) {
  EXPECT_EQ(TwoViewRestartFrame(TwoViewBootstrapFailure("", 12, 5), true), 12);
  EXPECT_EQ(TwoViewRestartFrame(TwoViewBootstrapFailure("", 12, 5), false), 12);
  EXPECT_EQ(TwoViewRestartFrame(TwoViewBootstrapFailure("", 0, -1), false), 1);
  EXPECT_EQ(TwoViewRestartFrame(TwoViewBootstrapFailure("", -1, 7), true), 7);
  EXPECT_EQ(TwoViewRestartFrame(TwoViewBootstrapFailure("", -1, 7), false), -1);
  EXPECT_EQ(TwoViewRestartFrame(TwoViewBootstrapFailure("", -1, -1), true), -1);
}

// Corners lost after frames passed the parallax gates (a frame of noise after the near-rotation
// start's frames) fix the direction roughly over the frames they lasted: their tracks go to the
// random start's choice when they lasted over its random_start_frames, as when the direction
// gate fails; lost earlier, they would leave its later frames (where a wrong start shows)
// unchecked, and none go.
TEST(TwoViewBootstrapTest, CornersLostAfterTheParallaxGatesCheckTheRandomStartOverItsFrames) {
  constexpr int kLowtexFrames = 12;
  const synthetic::SynthOptions options = test::SmallLowtexOptions(150);
  const synthetic::SyntheticSequence sequence = synthetic::MakeSequence(options);
  std::vector<cv::Mat> images = NearRotationFrames(sequence, kLowtexFrames);
  cv::Mat noise(images[0].size(), CV_32F);
  cv::RNG(7).fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  images.push_back(noise);
  std::vector<int> frames(kLowtexFrames + 1);
  std::iota(frames.begin(), frames.end(), 0);
  const RenderedDataset dataset(sequence, images, frames);
  OdometryConfig direction_gate;
  direction_gate.odometry.two_view_corner_quality = 0.01;
  direction_gate.odometry.two_view_corner_min_distance_px = 7.0;
  direction_gate.odometry.two_view_min_rotation_free_parallax_px = 0.0;
  const auto run = [&](int random_start_frames, CornerTracks* unsettled) {
    OdometryConfig config = direction_gate;
    config.odometry.random_start_frames = random_start_frames;
    return Outcome(dataset, config, kLowtexFrames + 1, unsettled);
  };

  CornerTracks unsettled;
  const std::string why = run(kLowtexFrames, &unsettled);
  EXPECT_NE(why.find("corners left at frame 12"), std::string::npos) << why;
  EXPECT_NE(why.find("fixes the translation direction"), std::string::npos) << why;
  int to_frame_11 = 0;
  for (const std::vector<cv::Point2f>& track : unsettled.positions) {
    to_frame_11 += track.size() >= static_cast<size_t>(kLowtexFrames);
  }
  EXPECT_GE(to_frame_11, direction_gate.odometry.two_view_min_inliers);

  CornerTracks too_short;
  const std::string lost_early = run(kLowtexFrames + 1, &too_short);
  EXPECT_NE(lost_early.find("corners left at frame 12"), std::string::npos) << lost_early;
  EXPECT_TRUE(too_short.positions.empty());
}

// Frame 0's corners lost early (a blank frame 6 loses every track, the next frames are the
// render's again): with random_start_reanchored_corners, corners detected again where the newest
// anchor's were lost (the blank frame has none, so frame 7) check the random start's later frames;
// without it, none go.
TEST(TwoViewBootstrapTest, CornersLostEarlyAreDetectedAgainForTheRandomStart) {
  constexpr int kFramesRun = 21, kBlank = 6;
  const synthetic::SynthOptions options = test::SmallLowtexOptions(150);
  const synthetic::SyntheticSequence sequence = synthetic::MakeSequence(options);
  std::vector<cv::Mat> images = NearRotationFrames(sequence, kFramesRun);
  images.push_back(cv::Mat(images[0].size(), CV_32F, cv::Scalar(128.0f)));
  std::vector<int> frames(kFramesRun);
  std::iota(frames.begin(), frames.end(), 0);
  frames[kBlank] = kFramesRun;
  const RenderedDataset dataset(sequence, images, frames);
  OdometryConfig config;
  config.odometry.random_start_frames = kFramesRun;

  CornerTracks none;
  const std::string why = Outcome(dataset, config, kFramesRun, &none);
  EXPECT_NE(why.find("corners left at frame 6"), std::string::npos) << why;
  EXPECT_TRUE(none.positions.empty());

  config.odometry.random_start_reanchored_corners = true;
  CornerTracks reanchored;
  const std::string again = Outcome(dataset, config, kFramesRun, &reanchored);
  EXPECT_NE(again.find("corners detected again from frame 6"), std::string::npos) << again;
  ASSERT_EQ(reanchored.anchors.size(), reanchored.positions.size());
  std::map<int, int> alive_at_end;  // per anchor, the tracks that reach the last frame
  for (size_t i = 0; i < reanchored.positions.size(); ++i) {
    const int anchor = reanchored.Anchor(i);
    ASSERT_TRUE(anchor == 0 || anchor == kBlank + 1) << anchor;
    const int last = anchor + static_cast<int>(reanchored.positions[i].size()) - 1;
    ASSERT_LE(last, anchor == 0 ? kBlank - 1 : kFramesRun - 1);
    alive_at_end[anchor] += last == kFramesRun - 1;
  }
  EXPECT_GE(alive_at_end[kBlank + 1], config.odometry.two_view_min_inliers);
  // The ground-truth motion fits them to the tracking's accuracy, over both anchors.
  std::vector<SE3> truth;
  for (int k = 0; k < kFramesRun; ++k) truth.push_back(sequence.ground_truth[k].world_from_cam);
  const double truth_px = CornerEpipolarErrorPx(reanchored, truth, dataset.camera());
  std::printf("re-anchored corners' epipolar error against the ground truth: %.3f px\n", truth_px);
  EXPECT_LT(truth_px, 0.5);
}

// An auto-exposure camera: frame k's intensities scaled by a gain that swings +-30% about 1 and
// shifted by an offset, saturating at 0 and 255 as a sensor does.
std::vector<cv::Mat> WithExposureSwings(const std::vector<cv::Mat>& images) {
  std::vector<cv::Mat> exposed;
  for (size_t k = 0; k < images.size(); ++k) {
    const double gain = 1.0 + 0.3 * std::sin(0.9 * static_cast<double>(k));
    cv::Mat image = images[k] * gain + 10.0 * std::cos(0.7 * static_cast<double>(k));
    cv::min(cv::max(image, 0.0), 255.0, image);
    exposed.push_back(image);
  }
  return exposed;
}

// LK has no gain term: on these frames plain LK loses every corner by frame 35. With each frame's
// exposure change fitted to the tracked patches and undone (brightness_change.h), the start is the
// steady one's to within a frame.
TEST(TwoViewBootstrapTest, ExposureSwingsLeaveTheCornerTracks) {
  const TexturedSequence textured = Textured(kFrames);
  std::vector<int> frames;
  for (int i = 0; i < kFrames; ++i) frames.push_back(i);
  const RenderedDataset steady(textured.sequence, textured.images, frames);
  const RenderedDataset swinging(textured.sequence, WithExposureSwings(textured.images), frames);
  OdometryConfig corners_only;
  corners_only.odometry.two_view_photometric_passes = 0;
  const TwoViewBootstrap reference = BootstrapFromTwoViews(steady, corners_only, kFrames);
  const TwoViewBootstrap result = BootstrapFromTwoViews(swinging, corners_only, kFrames);
  const BootstrapErrors reference_errors = Evaluate(reference, steady, textured.first_depth);
  const BootstrapErrors errors = Evaluate(result, swinging, textured.first_depth);
  Print("steady exposure", reference, reference_errors);
  Print("exposure swings", result, errors);
  ASSERT_GT(result.second_view, 0);
  EXPECT_LE(std::abs(result.second_view - reference.second_view), 1);
  EXPECT_GE(result.tracks, 0.9 * reference.tracks);
  EXPECT_LT(errors.direction_deg, 3.0 * result.direction_std_deg);
  EXPECT_LT(errors.rotation_deg, 0.5);
}

TEST(TwoViewBootstrapTest, BlankFrameHasNoCorners) {
  const TexturedSequence textured = Textured(1);
  const RenderedDataset blank(textured.sequence,
                              {cv::Mat(textured.images[0].size(), CV_32F, cv::Scalar(128))},
                              std::vector<int>(kFrames, 0));
  try {
    BootstrapFromTwoViews(blank, OdometryConfig(), kFrames);
    FAIL() << "a blank frame must not bootstrap";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("corners"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pldvo
