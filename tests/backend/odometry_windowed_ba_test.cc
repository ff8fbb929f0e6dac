// The odometry with windowed photometric + line bundle adjustment (backend.windowed_ba.enabled)
// on the short synthetic sequence of odometry_edge_ba_test.cc (320x240, lowtex preset, a
// keyframe at least every 6 frames). Deterministic single-thread mode, where the BA runs
// synchronously when a new keyframe's first map is published: one window per keyframe after the
// first, applied; the frames tracked against a keyframe are anchored to its refined pose; depth
// corrections reach the depth filter; the run is repeatable; the trajectory and the keyframe
// poses are not worse than without the BA beyond stated tolerances. With the mapping thread the
// BA runs on its worker thread (exercised, counts only). Also: the config section reads from
// YAML / --set and rejects unknown keys, bad values and both BAs at once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "backend/odometry/odometry.h"
#include "backend/odometry/odometry_config.h"
#include "core/config_io.h"
#include "core/evaluation.h"
#include "tests/backend/rendered_sequence.h"
#include "tests/sanitizer_budget.h"

namespace pldvo {
namespace {

// The runs but the accuracy test's: 30 frames (5 keyframes, 4 windows); under the sanitizers
// (about 10x slower) 20 frames, at least two windows, of the 36-frame sequence that
// odometry_test.cc renders too (one rendering per ctest run through the render cache; the
// accuracy test, which needs 48, is Release-only there).
#ifdef PLDVO_SANITIZE
constexpr int kFrames = 36;
constexpr int kRunFrames = 20;
#else
constexpr int kFrames = 48;
constexpr int kRunFrames = 30;
#endif

using test::RenderedSequence;

const RenderedSequence& Sequence() {
  static const RenderedSequence rendered = test::RenderLowtexSequence(kFrames);
  return rendered;
}

// Deterministic (inline mapping, synchronous BA), the first keyframe from the rendered depth (as
// in odometry_test.cc), a keyframe at least every 6 frames. Windows of 7 keyframes with up to
// 500 points (the sequence's images are a quarter of 640x480, and the tests run under the
// sanitizers).
OdometryConfig Config(bool windowed_ba, bool parallel = false) {
  OdometryConfig config;
  config.odometry.parallel_mapping = parallel;
  config.odometry.init_depth_idepth_var = 1e-4;
  config.keyframes.max_frames = 6;
  config.backend.windowed_ba.enabled = windowed_ba;
  config.backend.windowed_ba.max_points = 500;
  return config;
}

struct RunResult {
  std::vector<OdometryFrameResult> frames;
  OdometryStatistics stats;
  Trajectory estimate;  // tracked frames
  std::vector<KeyframePoseRecord> keyframes;
  std::vector<double> ba_ms;
};

RunResult RunSequence(const OdometryConfig& config, int frames = kRunFrames) {
  const RenderedSequence& rendered = Sequence();
  Odometry odometry(rendered.sequence.camera, config);
  RunResult run;
  for (int i = 0; i < frames; ++i) {
    const double timestamp = rendered.sequence.ground_truth[i].timestamp;
    run.frames.push_back(odometry.ProcessFrame(i, timestamp, rendered.images[i],
                                               i == 0 ? rendered.first_depth : cv::Mat()));
    if (IsTracked(run.frames.back().status)) {
      run.estimate.push_back({timestamp, run.frames.back().world_from_cam});
    }
  }
  odometry.Finish();
  run.stats = odometry.statistics();
  run.keyframes = odometry.WindowedBAKeyframePoses();
  run.ba_ms = odometry.WindowedBATimesMs();
  return run;
}

double TranslationDistance(const SE3& a, const SE3& b) {
  return (a.translation() - b.translation()).norm();
}

TEST(OdometryWindowedBATest, SolvesAWindowPerKeyframeAndAnchorsTrackingToIt) {
  const RunResult run = RunSequence(Config(true));
  for (const OdometryFrameResult& frame : run.frames) {
    EXPECT_TRUE(IsTracked(frame.status))
        << "frame " << frame.index << ": " << FrameStatusName(frame.status) << " " << frame.message;
  }
  // A window when each keyframe's first map arrives (at the next frame), from the second
  // keyframe on; the last keyframe may be the last frame.
  ASSERT_GE(run.stats.keyframes, 3);
  EXPECT_GE(run.stats.windowed_ba_windows, run.stats.keyframes - 2);
  EXPECT_LE(run.stats.windowed_ba_windows, run.stats.keyframes - 1);
  EXPECT_EQ(run.stats.windowed_ba_applied, run.stats.windowed_ba_windows);
  EXPECT_EQ(run.stats.windowed_ba_failures, 0);
  EXPECT_EQ(run.ba_ms.size(), static_cast<size_t>(run.stats.windowed_ba_windows));
  // Depth feedback: a job per applied window that had points of the current keyframe, and the
  // depth filter shifted hypotheses.
  EXPECT_GT(run.stats.windowed_ba_idepth_jobs, 0);
  EXPECT_GT(run.stats.windowed_ba_idepths_corrected, 0);
  ASSERT_EQ(static_cast<int>(run.keyframes.size()), run.stats.keyframes);

  // Inline, a keyframe's pose moves at the window of its first map (before the next frame is
  // tracked) and next at windows of later keyframes, when it is no longer tracked against. So
  // every frame tracked against keyframe K satisfies world_from_frame * frame_from_K = the same
  // pose of K, the pose after its window, which differs from the pose K was created with.
  std::map<int, SE3> created;                // keyframe id -> pose when created
  std::map<int, std::vector<SE3>> anchored;  // keyframe id -> world_from_cam * cur_from_ref
  for (const OdometryFrameResult& frame : run.frames) {
    if (frame.status == FrameStatus::kKeyframe) {
      created[frame.keyframe_id] = frame.world_from_cam;
    } else if (IsTracked(frame.status)) {
      anchored[frame.keyframe_id].push_back(frame.world_from_cam * frame.tracking.cur_from_ref);
    }
  }
  int moved = 0;
  for (const auto& [id, poses] : anchored) {
    SCOPED_TRACE("keyframe " + std::to_string(id));
    ASSERT_TRUE(created.count(id));
    for (const SE3& pose : poses) {
      // Rounding of the composition only.
      EXPECT_LT(TranslationDistance(pose, poses.front()), 1e-9);
    }
    // The first keyframe is the window's gauge (held) and its first window has none before it.
    if (id > 0 && TranslationDistance(poses.front(), created[id]) > 1e-6) ++moved;
  }
  EXPECT_GE(moved, 1);
  // The recorded keyframe poses moved too, and the first keyframe (the gauge of its windows)
  // did not.
  EXPECT_LT(TranslationDistance(run.keyframes.front().world_from_kf, created[0]), 1e-12);
}

// marginalize with a window of 3: from the window after the first full one, each window carries
// the prior its predecessor left (its oldest keyframe marginalised), and every window applies.
TEST(OdometryWindowedBATest, MarginalisedKeyframesLeaveAPriorForTheNextWindow) {
  OdometryConfig config = Config(true);
  config.backend.windowed_ba.window = 3;
  config.backend.windowed_ba.marginalize = true;
  const RunResult run = RunSequence(config);
  for (const OdometryFrameResult& frame : run.frames) EXPECT_TRUE(IsTracked(frame.status));
  ASSERT_GE(run.stats.windowed_ba_windows, 3);
  EXPECT_EQ(run.stats.windowed_ba_applied, run.stats.windowed_ba_windows);
  EXPECT_EQ(run.stats.windowed_ba_failures, 0);
  // Windows 1 and 2 grow to 3 keyframes; from the third on each has a prior.
  EXPECT_EQ(run.stats.windowed_ba_prior_windows, run.stats.windowed_ba_windows - 2);
}

// leaving: spread with a window of 3 (keyframes may leave out of order): every window applies and
// the keyframe poses come out once each, in time order.
TEST(OdometryWindowedBATest, SpreadWindowsApplyAndKeyframesComeOutInTimeOrder) {
  OdometryConfig config = Config(true);
  config.backend.windowed_ba.window = 3;
  config.backend.windowed_ba.leaving = LeavingKeyframe::kSpread;
  const RunResult run = RunSequence(config);
  for (const OdometryFrameResult& frame : run.frames) EXPECT_TRUE(IsTracked(frame.status));
  ASSERT_GE(run.stats.windowed_ba_windows, 3);
  EXPECT_EQ(run.stats.windowed_ba_applied, run.stats.windowed_ba_windows);
  ASSERT_EQ(static_cast<int>(run.keyframes.size()), run.stats.keyframes);
  for (size_t k = 1; k < run.keyframes.size(); ++k) {
    EXPECT_LT(run.keyframes[k - 1].frame_index, run.keyframes[k].frame_index);
  }
}

// backend.windowed_ba.weighting.intensity_noise estimated: every window weighs its photometric
// rows with the sigma_I that tracking estimated, so the BA's sigma_intensity no longer matters;
// fixed, it does (8 frames, two windows).
TEST(OdometryWindowedBATest, EstimatedIntensityNoiseComesFromTracking) {
  auto keyframe_poses = [](bool estimated, double sigma_intensity) {
    OdometryConfig config = Config(true);
    WeightingOptions& weighting = config.backend.windowed_ba.weighting;
    weighting.intensity_noise = estimated ? NoiseSource::kEstimated : NoiseSource::kFixed;
    weighting.sigma_intensity = sigma_intensity;
    const RunResult run = RunSequence(config, 8);
    EXPECT_GE(run.stats.windowed_ba_applied, 1);
    std::vector<Eigen::Vector3d> centres;
    for (const KeyframePoseRecord& keyframe : run.keyframes) {
      centres.push_back(keyframe.world_from_kf.translation());
    }
    return centres;
  };
  const std::vector<Eigen::Vector3d> estimated = keyframe_poses(true, 4.0);
  EXPECT_EQ(keyframe_poses(true, 1000.0), estimated);
  EXPECT_NE(keyframe_poses(false, 4.0), estimated);
}

TEST(OdometryWindowedBATest, SynchronousModeRepeatsExactly) {
  const RunResult a = RunSequence(Config(true));
  const RunResult b = RunSequence(Config(true));
  ASSERT_GE(a.stats.windowed_ba_applied, 2);
  ASSERT_EQ(a.estimate.size(), b.estimate.size());
  for (size_t i = 0; i < a.estimate.size(); ++i) {
    EXPECT_EQ(a.estimate[i].world_from_cam.translation(),
              b.estimate[i].world_from_cam.translation());
  }
  ASSERT_EQ(a.keyframes.size(), b.keyframes.size());
  for (size_t i = 0; i < a.keyframes.size(); ++i) {
    EXPECT_EQ(a.keyframes[i].world_from_kf.translation(),
              b.keyframes[i].world_from_kf.translation());
  }
}

TEST(OdometryWindowedBATest, IsNotWorseThanWithout) {
  PLDVO_RELEASE_ONLY_ACCURACY_TEST("OdometryWindowedBATest.SynchronousModeRepeatsExactly");
  const RunResult without = RunSequence(Config(false), kFrames);
  const RunResult with = RunSequence(Config(true), kFrames);
  EXPECT_EQ(without.stats.windowed_ba_windows, 0);
  EXPECT_TRUE(without.keyframes.empty());
  const Trajectory& all = Sequence().sequence.ground_truth;
  const Trajectory ground_truth(all.begin(), all.begin() + kFrames);
  const EvaluationResult eval_without = EvaluateTrajectory(ground_truth, without.estimate);
  const EvaluationResult eval_with = EvaluateTrajectory(ground_truth, with.estimate);
  EXPECT_DOUBLE_EQ(eval_with.coverage, 1.0);
  // Keyframe poses: without the BA (its run's keyframe frames), and in the run with it as tracked
  // (the keyframe frames' output poses) and after the last window that held them.
  Trajectory keyframes_without, keyframes_tracked, keyframes_ba;
  for (const OdometryFrameResult& frame : without.frames) {
    if (frame.status == FrameStatus::kKeyframe) {
      keyframes_without.push_back({frame.timestamp, frame.world_from_cam});
    }
  }
  for (const KeyframePoseRecord& keyframe : with.keyframes) {
    keyframes_ba.push_back({keyframe.timestamp, keyframe.world_from_kf});
    keyframes_tracked.push_back(
        {keyframe.timestamp, with.frames[keyframe.frame_index].world_from_cam});
  }
  const double ate_without = EvaluateTrajectory(ground_truth, keyframes_without).ate_m;
  const double ate_tracked = EvaluateTrajectory(ground_truth, keyframes_tracked).ate_m;
  const double ate_ba = EvaluateTrajectory(ground_truth, keyframes_ba).ate_m;
  std::printf(
      "ATE mm / RPE cm/s / RPE deg/s: without BA %.2f / %.2f / %.3f, with BA %.2f / %.2f / %.3f; "
      "keyframe ATE mm without BA %.2f, with BA as tracked %.2f, after BA %.2f; %d windows\n",
      1e3 * eval_without.ate_m, eval_without.rpe_cm_s, eval_without.rpe_deg_s,
      1e3 * eval_with.ate_m, eval_with.rpe_cm_s, eval_with.rpe_deg_s, 1e3 * ate_without,
      1e3 * ate_tracked, 1e3 * ate_ba, with.stats.windowed_ba_windows);
  // Measured without -> with (window 7, 500 points; 2026-12-06): frames ATE 1.06 -> 3.16 mm, RPE
  // 0.56 -> 0.66 cm/s and 0.223 -> 0.217 deg/s; keyframes ATE 1.00 mm without, 2.84 as tracked
  // and 0.59 after the BA with it (with the depth filter's variance in the rows' weights,
  // depth_variance_in_weights, earlier code: 0.83, 2.14, 0.94; window 5: frames 1.46 mm, 0.37 cm/s;
  // keyframes 1.36 -> 0.62 mm; the development set prefers 7, docs/windowed_ba.md). (Before the
  // pattern fix of the builder, whose DSO pattern had collapsed onto the centre pixel in the -O3
  // build, the BA moved the keyframes away: 3.16 -> 3.28 mm.) Tracking is accurate to millimetres
  // here, near the rendering's floor for the BA (docs/windowed_ba.md). What the bounds hold: the
  // keyframes after the BA are closer to the truth than as tracked in the same run, within 2 mm of
  // the run without the BA, and the frames within 3 mm ATE, 0.8 cm/s and 0.2 deg/s RPE of it
  // (keyframes about 5 cm apart).
  EXPECT_LT(ate_ba, ate_tracked);
  EXPECT_LT(ate_ba, ate_without + 0.002);
  EXPECT_LT(eval_with.ate_m, eval_without.ate_m + 0.003);
  EXPECT_LT(eval_with.rpe_cm_s, eval_without.rpe_cm_s + 0.8);
  EXPECT_LT(eval_with.rpe_deg_s, eval_without.rpe_deg_s + 0.2);
}

TEST(OdometryWindowedBATest, MappingThreadSolvesOnTheWorker) {
  const RunResult run = RunSequence(Config(true, /*parallel=*/true));
  int tracked = 0;
  for (const OdometryFrameResult& frame : run.frames) tracked += IsTracked(frame.status);
  EXPECT_EQ(tracked, static_cast<int>(run.frames.size()));
  // How many windows the worker solves before Finish depends on the schedule; at least one
  // (Finish waits for the queue), every one polled and none failed.
  EXPECT_GE(run.stats.windowed_ba_windows, 1);
  EXPECT_EQ(run.stats.windowed_ba_failures, 0);
  EXPECT_EQ(run.ba_ms.size(), static_cast<size_t>(run.stats.windowed_ba_windows));
}

TEST(OdometryWindowedBATest, ConfigSectionReadsAndRejectsUnknownKeys) {
  OdometryConfig config;
  EXPECT_FALSE(config.backend.windowed_ba.enabled);  // off by default
  ApplyOverrides({"backend.windowed_ba.enabled=true", "backend.windowed_ba.window=4",
                  "backend.windowed_ba.max_points=500", "backend.windowed_ba.solver=gauss_newton"},
                 &config);
  EXPECT_TRUE(config.backend.windowed_ba.enabled);
  EXPECT_EQ(config.backend.windowed_ba.window, 4);
  EXPECT_EQ(config.backend.windowed_ba.max_points, 500);
  EXPECT_EQ(config.backend.windowed_ba.solver, WindowedBASolver::kGaussNewton);
  EXPECT_EQ(config.Check(), "");
  EXPECT_THROW(ApplyOverrides({"backend.windowed_ba.windoww=4"}, &config), std::exception);
  EXPECT_EQ(config.backend.windowed_ba.window, 4);
  config.backend.windowed_ba.window = 1;
  EXPECT_NE(config.Check().find("windowed_ba: window"), std::string::npos) << config.Check();
  config.backend.windowed_ba.window = 4;
  ApplyOverrides({"backend.windowed_ba.leaving=spread"}, &config);
  EXPECT_EQ(config.backend.windowed_ba.leaving, LeavingKeyframe::kSpread);
  EXPECT_EQ(config.Check(), "");
  config.backend.windowed_ba.marginalize = true;
  EXPECT_NE(config.Check().find("leaving: spread needs marginalize false"), std::string::npos)
      << config.Check();
  config.backend.windowed_ba.marginalize = false;
  config.backend.edge_ba.enabled = true;
  EXPECT_NE(config.Check().find("cannot both be enabled"), std::string::npos) << config.Check();
}

}  // namespace
}  // namespace pldvo
