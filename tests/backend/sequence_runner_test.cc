// Tests of SequenceRunner (backend/odometry/sequence_runner.h), in-process: the run loop writes
// every output, the ground truth it writes gives evo the same comparison as the run's own
// evaluation, the windowed BA's outputs, a two-view start re-anchored after its corners are lost
// (backward_start.h), and an output that cannot be written stops the run with RunOutputError.
#include "backend/odometry/sequence_runner.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "backend/odometry/backward_start.h"
#include "core/evaluation.h"
#include "core/trajectory_io.h"
#include "tests/experiments/test_folder.h"
#include "tests/render_cache.h"
#include "tests/small_lowtex_options.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;
constexpr int kFrames = 36;  // 1.2 s: RPE needs pairs 1 s apart

fs::path SequenceDir() {
  static const fs::path dir = [] {
    synthetic::SynthOptions options = test::SmallLowtexOptions(kFrames);
#ifdef PLDVO_SANITIZE
    options.supersampling = 1;  // rendering dominates this test under the sanitizers
#endif
    return test::SequenceFolderForTest(options, test::TestRoot() / "lowtex");
  }();
  return dir;
}

OdometryConfig DeterministicConfig() {
  OdometryConfig config;
  config.odometry.parallel_mapping = false;
  config.odometry.random_start_candidates = 1;  // one start: the choice is run_command_test's
  return config;
}

TEST(SequenceRunnerTest, WritesEveryOutputAndAGroundTruthEvoCanCompare) {
  const std::unique_ptr<Dataset> dataset = OpenDataset(SequenceDir().string());
  SequenceRunOptions options;
  options.out_dir = (test::TestRoot() / "runner_all").string();
  options.dataset_label = SequenceDir().string();
  options.max_frames = 0;  // all: RPE needs pairs 1 s apart
  SequenceRunner runner(*dataset, DeterministicConfig(), options);
  const SequenceRunResult result = runner.Run();

  EXPECT_EQ(result.frames, kFrames);
  EXPECT_EQ(result.tracked, kFrames);
  EXPECT_EQ(result.failed, 0);
  EXPECT_EQ(result.summary["frames"], kFrames);
  for (const char* file : {"config.yaml", "trajectory.txt", "groundtruth.txt", "timing.csv",
                           "summary.json", "trajectory.svg"}) {
    EXPECT_TRUE(fs::exists(fs::path(options.out_dir) / file)) << file;
  }
  const Trajectory estimate = ReadTrajectoryTum(options.out_dir + "/trajectory.txt");
  ASSERT_EQ(estimate.size(), static_cast<size_t>(kFrames));
  // groundtruth.txt is the dataset's ground truth, in the trajectory's frame and format: the
  // comparison of the two files (what evo does) is the run's own evaluation.
  const Trajectory ground_truth = ReadTrajectoryTum(options.out_dir + "/groundtruth.txt");
  ASSERT_EQ(ground_truth.size(), dataset->ground_truth()->size());
  const EvaluationResult from_files = EvaluateTrajectory(ground_truth, estimate);
  ASSERT_TRUE(result.summary["rpe_cm_s"].is_number());
  // The TUM files hold the shortest decimals that read back exactly (trajectory_io.h): only the
  // summary's JSON round trip separates the two.
  EXPECT_NEAR(from_files.rpe_cm_s, result.summary["rpe_cm_s"].get<double>(), 1e-9);
  EXPECT_NEAR(from_files.ate_m, result.summary["ate_m"].get<double>(), 1e-12);
  // The stereo's counts: every successful observation (SSD or line-guided) is fused, rejected by
  // the gate, creates a hypothesis or is too uncertain to create one; no search is skipped by
  // default.
  const nlohmann::json& stereo = result.summary["stereo"];
  EXPECT_GT(stereo["ssd_attempts"].get<int64_t>(), 10000);
  EXPECT_GT(stereo["line_ok"].get<int64_t>(), 1000);
  EXPECT_EQ(stereo["fused"].get<int64_t>() + stereo["outliers"].get<int64_t>() +
                stereo["created"].get<int64_t>() + stereo["not_created"].get<int64_t>(),
            stereo["ssd_ok"].get<int64_t>() + stereo["line_ok"].get<int64_t>());
  EXPECT_EQ(stereo["ssd_skipped"].get<int64_t>(), 0);
  // The plot has the ground truth and the aligned estimate.
  std::stringstream svg;
  svg << std::ifstream(options.out_dir + "/trajectory.svg").rdbuf();
  EXPECT_NE(svg.str().find("<svg"), std::string::npos);
  EXPECT_NE(svg.str().find("Sim(3)-aligned"), std::string::npos);
  // The report: counts, the component table, the evaluation, the output folder.
  ASSERT_GE(result.report.size(), 3u);
  EXPECT_NE(result.report[0].find("36 frames, 36 tracked"), std::string::npos) << result.report[0];
}

// backend.windowed_ba: keyframes_ba.txt has a pose per keyframe, trajectory_ba.txt every tracked
// frame re-anchored to its keyframe's final pose (a keyframe frame takes that pose exactly), and
// summary.json `windowed_ba` counts the windows.
TEST(SequenceRunnerTest, WindowedBAWritesKeyframeAndReanchoredTrajectories) {
  const std::unique_ptr<Dataset> dataset = OpenDataset(SequenceDir().string());
  SequenceRunOptions options;
  options.out_dir = (test::TestRoot() / "runner_windowed_ba").string();
  options.dataset_label = SequenceDir().string();
  options.max_frames = 24;  // 4 keyframes, 3 windows
  OdometryConfig config = DeterministicConfig();
  config.keyframes.max_frames = 6;
  config.backend.windowed_ba.enabled = true;
  config.backend.windowed_ba.max_points = 500;
  SequenceRunner runner(*dataset, config, options);
  const SequenceRunResult result = runner.Run();
  ASSERT_TRUE(result.summary.contains("windowed_ba"));
  const nlohmann::json& ba = result.summary["windowed_ba"];
  const int keyframes = result.summary["keyframes"].get<int>();
  EXPECT_GE(ba["windows"].get<int>(), 2);
  EXPECT_EQ(ba["applied"], ba["windows"]);
  const Trajectory keyframes_ba = ReadTrajectoryTum(options.out_dir + "/keyframes_ba.txt");
  EXPECT_EQ(static_cast<int>(keyframes_ba.size()), keyframes);
  const Trajectory estimate = ReadTrajectoryTum(options.out_dir + "/trajectory.txt");
  const Trajectory reanchored = ReadTrajectoryTum(options.out_dir + "/trajectory_ba.txt");
  ASSERT_EQ(reanchored.size(), estimate.size());
  int keyframe_frames = 0;
  for (const StampedPose& keyframe : keyframes_ba) {
    for (const StampedPose& pose : reanchored) {
      if (pose.timestamp != keyframe.timestamp) continue;
      ++keyframe_frames;
      // The TUM files' shortest exact decimals: equal to rounding of the quaternion round trip.
      EXPECT_LT((pose.world_from_cam.translation() - keyframe.world_from_cam.translation()).norm(),
                1e-12);
    }
  }
  EXPECT_EQ(keyframe_frames, keyframes);
}

// A dataset whose frame `blank` is one gray level: no corner, no gradient.
class WithBlankFrame : public Dataset {
 public:
  WithBlankFrame(const Dataset& dataset, int blank) : dataset_(dataset), blank_(blank) {}
  std::string format() const override { return dataset_.format(); }
  int size() const override { return dataset_.size(); }
  double timestamp(int i) const override { return dataset_.timestamp(i); }
  Frame Load(int i) const override {
    Frame frame = dataset_.Load(i);
    if (i == blank_) frame.image.setTo(cv::Scalar(128.0));
    return frame;
  }
  const PinholeCamera& camera() const override { return dataset_.camera(); }
  const Trajectory* ground_truth() const override { return dataset_.ground_truth(); }

 private:
  const Dataset& dataset_;
  const int blank_;
};

// odometry.two_view_max_anchor: frame 2 is blank, so frame 0's corners are lost there and frame 2
// has none; the two-view start begins at frame 3 and finds its second view (frame 26), and frames
// 0 and 1 are tracked backwards from frame 3's map: one trajectory, in one scale (ATE 0.5 mm),
// with one lost event (the blank frame).
TEST(SequenceRunnerTest, TwoViewStartReanchoredAfterItsCornersAreLost) {
  synthetic::SynthOptions synth = test::SmallLowtexOptions(kFrames);
  synth.preset = "textured";
  synth.seed = 2;
#ifdef PLDVO_SANITIZE
  synth.supersampling = 1;  // rendering dominates under the sanitizers (second view 32, 0.8 mm)
#endif
  const fs::path folder = test::SequenceFolderForTest(synth, test::TestRoot() / "textured2");
  const std::unique_ptr<Dataset> rendered = OpenDataset(folder.string());
  const WithBlankFrame dataset(*rendered, 2);
  SequenceRunOptions options;
  options.out_dir = (test::TestRoot() / "runner_reanchored").string();
  options.dataset_label = folder.string();
  OdometryConfig config = DeterministicConfig();
  config.odometry.two_view_max_anchor = 10;
  config.odometry.compare_solver = OdometryOptions::CompareSolver::kCeres;
  SequenceRunner runner(dataset, config, options);
  const SequenceRunResult result = runner.Run();

  const nlohmann::json& two_view = result.summary["two_view_bootstrap"];
  ASSERT_TRUE(two_view.is_object()) << result.summary.dump(2);
  EXPECT_EQ(two_view["anchor"], 3);
  EXPECT_GT(two_view["second_view"].get<int>(), 3);
  EXPECT_EQ(two_view["backward"]["frames"], 3);
  EXPECT_EQ(two_view["backward"]["tracked"], 2);  // frames 1 and 0; the blank one is lost
  EXPECT_EQ(result.tracked, kFrames - 1);
  EXPECT_EQ(result.summary["lost_events"], 1);
  EXPECT_EQ(result.summary["scale_segments"], 1);
  const Trajectory estimate = ReadTrajectoryTum(options.out_dir + "/trajectory.txt");
  ASSERT_EQ(estimate.size(), static_cast<size_t>(kFrames - 1));
  EXPECT_DOUBLE_EQ(estimate[0].timestamp, dataset.timestamp(0));
  EXPECT_DOUBLE_EQ(estimate[2].timestamp, dataset.timestamp(3));
  EXPECT_TRUE(estimate[2].world_from_cam.translation().isZero());  // the anchor is the world
  // Frames 0-1 and 3-35 in one scale: the Sim(3)-aligned trajectory follows the ground truth
  // to a fraction of the 1.2 s path (about 0.3 m at this render's speed).
  // The solver comparison's trajectory has the same frames: those before the anchor as the run's.
  const Trajectory compared = ReadTrajectoryTum(options.out_dir + "/trajectory_compare.txt");
  ASSERT_EQ(compared.size(), estimate.size());
  const int compared_frames = result.summary["compare_solver"]["frames_compared"].get<int>();
  EXPECT_GT(compared_frames, 0);
  EXPECT_LE(compared_frames, kFrames - 4);  // not frames 0-3
  for (int i = 0; i < 2; ++i) {
    EXPECT_TRUE(compared[i].world_from_cam.translation().isApprox(
        estimate[i].world_from_cam.translation()));
  }
  const EvaluationResult eval = EvaluateTrajectory(*dataset.ground_truth(), estimate);
  std::printf("re-anchored at frame 3: ATE %.4f m, RPE %.3f cm/s\n", eval.ate_m, eval.rpe_cm_s);
  EXPECT_LT(eval.ate_m, 0.005);
}

TEST(SequenceRunnerTest, ABackwardStartNeedsALaterFrame) {
  const std::unique_ptr<Dataset> dataset = OpenDataset(SequenceDir().string());
  EXPECT_THROW(TrackBackwardFromAnchor(*dataset, DeterministicConfig(), 0, cv::Mat()),
               std::invalid_argument);
  EXPECT_THROW(TrackBackwardFromAnchor(*dataset, DeterministicConfig(), kFrames, cv::Mat()),
               std::invalid_argument);
}

TEST(SequenceRunnerTest, AnOutputFolderThatCannotBeMadeIsAnOutputError) {
  const std::unique_ptr<Dataset> dataset = OpenDataset(SequenceDir().string());
  const fs::path blocker = test::TestRoot() / "a_file";
  std::ofstream(blocker) << "not a folder\n";
  SequenceRunOptions options;
  options.out_dir = (blocker / "out").string();
  options.max_frames = 2;
  SequenceRunner runner(*dataset, DeterministicConfig(), options);
  EXPECT_THROW(runner.Run(), RunOutputError);
}

}  // namespace
}  // namespace pldvo
