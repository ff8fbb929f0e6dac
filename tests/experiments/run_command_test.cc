// `pldvo run` and `pldvo ablate` end to end through the real binary (PLDVO_BINARY) on a tiny
// synthetic sequence written in the TUM layout (320x240, 36 frames): every output file, the
// survival of the trajectory across a corrupt frame mid-run, the ablation tables and plot, and
// the rejection of an unknown config key; a sharded grid collected equals one run. Runs use the
// deterministic single-thread mapping. `pldvo basin` with the frontend's lines on a few small-gap
// pairs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "backend/odometry/odometry_config.h"
#include "core/config_io.h"
#include "core/trajectory_io.h"
#include "experiments/synthetic/synthetic_sequence.h"
#include "tests/experiments/test_folder.h"
#include "tests/render_cache.h"
#include "tests/small_lowtex_options.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;
constexpr int kFrames = 36;  // 1.2 s: RPE needs pairs 1 s apart

using test::Pldvo;
using test::Slurp;
using test::TestRoot;

// The synthetic sequence (written once per ctest run, tests/render_cache.h; tests copy it before
// damaging it).
fs::path SequenceDir() {
  static const fs::path dir = [] {
    synthetic::SynthOptions options = test::SmallLowtexOptions(kFrames);
#ifdef PLDVO_SANITIZE
    options.supersampling = 1;  // rendering dominates these tests under the sanitizers
#endif
    return test::SequenceFolderForTest(options, TestRoot() / "lowtex");
  }();
  return dir;
}

int CountLines(const fs::path& path, bool skip_comments) {
  std::ifstream file(path);
  std::string line;
  int count = 0;
  while (std::getline(file, line)) {
    if (line.empty() || (skip_comments && line[0] == '#')) continue;
    ++count;
  }
  return count;
}

// Inline mapping, and one initial map: the choice among several random starts
// (RandomStartChoosesTheBestFittingInitialMap) would run these short sequences three more times.
const char* const kDeterministic =
    " --set odometry.parallel_mapping=false --set odometry.random_start_candidates=1";

// Rows of a CSV file with a header line, each split at commas.
std::vector<std::vector<std::string>> CsvRows(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);  // header
  while (std::getline(file, line)) {
    std::vector<std::string> fields;
    std::stringstream stream(line);
    std::string field;
    while (std::getline(stream, field, ',')) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.push_back("");  // getline drops the last
    rows.push_back(fields);
  }
  return rows;
}

TEST(RunCommandTest, WritesAllOutputs) {
  const fs::path out = TestRoot() / "run_all";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + out.string() +
                      kDeterministic + " --set output.keyframe_depth_png=true" +
                      " --set output.keyframe_ply=true --set output.iteration_images_every=10",
                  TestRoot() / "run_all.log"),
            0)
      << Slurp(TestRoot() / "run_all.log");
  // trajectory.txt: one TUM line per tracked frame (all of them on this sequence).
  const Trajectory trajectory = ReadTrajectoryTum((out / "trajectory.txt").string());
  EXPECT_EQ(trajectory.size(), static_cast<size_t>(kFrames));
  // timing.csv: a header and one row per frame; the line gates unmatch at most the matches.
  EXPECT_EQ(CountLines(out / "timing.csv", false), kFrames + 1);
  std::string header;
  std::getline(std::ifstream(out / "timing.csv"), header);
  EXPECT_EQ(header.rfind("index,timestamp,status,keyframe_id,lines,matches,line_outliers,", 0), 0u)
      << header;
  EXPECT_NE(header.find(",pose_sigma_t,pose_sigma_r_deg,intensity_noise_sigma,line_noise_scale,"),
            std::string::npos)
      << header;
  for (const std::vector<std::string>& row : CsvRows(out / "timing.csv")) {
    ASSERT_GT(row.size(), 6u);
    EXPECT_GE(std::stoi(row[6]), 0);
    EXPECT_LE(std::stoi(row[6]), std::stoi(row[5])) << "frame " << row[0];
  }
  // config.yaml: the effective config, loadable, with the override applied.
  OdometryConfig config;
  ASSERT_NO_THROW(LoadConfigYaml((out / "config.yaml").string(), &config));
  EXPECT_FALSE(config.odometry.parallel_mapping);
  // summary.json: counts, timing objects and the evaluation against the ground truth.
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  EXPECT_EQ(summary["frames"], kFrames);
  EXPECT_EQ(summary["tracked"], kFrames);
  EXPECT_GE(summary["keyframes"].get<int>(), 1);
  EXPECT_EQ(summary["lost_events"], 0);
  EXPECT_EQ(summary["scale_segments"], 1);
  for (const char* object : {"ms_median", "ms_mean"}) {
    for (const char* key : {"detection", "description", "matching", "tracking", "mapping",
                            "tracking_thread", "total"}) {
      ASSERT_TRUE(summary[object].contains(key)) << object << "." << key;
      EXPECT_GE(summary[object][key].get<double>(), 0.0);
    }
  }
  for (const char* key : {"rpe_cm_s", "rpe_deg_s", "ate_m", "coverage", "scale_drift",
                          "motion_rotation_error_deg_median", "motion_direction_error_deg_median",
                          "motion_rotation_ratio"}) {
    EXPECT_TRUE(summary[key].is_number()) << key;
  }
  // motion_errors.csv: a header and one row per motion between consecutive tracked frames.
  EXPECT_EQ(CountLines(out / "motion_errors.csv", false), kFrames);
  for (const std::vector<std::string>& row : CsvRows(out / "motion_errors.csv")) {
    ASSERT_EQ(row.size(), 6u);
    EXPECT_GE(std::stod(row[1]), 0.0);
  }
  ASSERT_TRUE(summary["window_scales"].is_array());
  EXPECT_FALSE(summary["window_scales"].empty());
  EXPECT_GE(summary["scale_drift"].get<double>(), 1.0);
  // Coverage: all frames; timestamps in rgb.txt carry 6 decimals, hence not exactly 1.
  EXPECT_NEAR(summary["coverage"].get<double>(), 1.0, 1e-3);
  // Optional outputs: keyframe PNG and PLY, iteration images of frames 10 and 20.
  EXPECT_TRUE(fs::exists(out / "keyframes" / "kf_0000_idepth.png"));
  EXPECT_TRUE(fs::exists(out / "keyframes" / "kf_0000.ply"));
  int iteration_images = 0;
  for (const auto& entry : fs::directory_iterator(out / "iterations")) {
    iteration_images += entry.path().extension() == ".png";
  }
  EXPECT_GT(iteration_images, 2);
}

TEST(RunCommandTest, CorruptFrameIsSkippedAndTheTrajectorySurvives) {
  // A copy of the sequence with frame 12's PNG replaced by garbage.
  const fs::path dataset = TestRoot() / "corrupt";
  fs::remove_all(dataset);
  fs::copy(SequenceDir(), dataset, fs::copy_options::recursive);
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(dataset / "rgb")) images.push_back(entry.path());
  std::sort(images.begin(), images.end());
  ASSERT_EQ(images.size(), static_cast<size_t>(kFrames));
  const fs::path broken = images[12];
  {
    std::ofstream file(broken, std::ios::trunc);
    file << "not a png";
  }
  const fs::path out = TestRoot() / "run_corrupt";
  const fs::path log = TestRoot() / "run_corrupt.log";
  ASSERT_EQ(
      Pldvo("run --dataset " + dataset.string() + " --out " + out.string() + kDeterministic, log),
      0)
      << Slurp(log);
  // The failure names the frame and its file; the run went on.
  const std::string text = Slurp(log);
  EXPECT_NE(text.find("frame 12"), std::string::npos) << text;
  EXPECT_NE(text.find(broken.filename().string()), std::string::npos) << text;
  // Every other frame is in the trajectory (tracking recovers right after the skipped frame).
  const Trajectory trajectory = ReadTrajectoryTum((out / "trajectory.txt").string());
  EXPECT_EQ(trajectory.size(), static_cast<size_t>(kFrames - 1));
  const std::string timing = Slurp(out / "timing.csv");
  EXPECT_NE(timing.find("\n12,"), std::string::npos);
  EXPECT_NE(timing.find(",failed,"), std::string::npos);
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  EXPECT_EQ(summary["failed_frames"], 1);
  EXPECT_EQ(summary["lost_events"], 1);
}

// odometry.frontend_thread: frame i + 1 prepared on the loading thread gives the same trajectory
// (a prefix of the sequence keeps the two runs cheap under the sanitizers).
TEST(RunCommandTest, FrontendThreadGivesTheSameTrajectory) {
  std::string trajectories[2];
  for (const bool frontend_thread : {false, true}) {
    const std::string name = std::string("run_frontend_thread_") + (frontend_thread ? "1" : "0");
    const fs::path out = TestRoot() / name;
    const fs::path log = TestRoot() / (name + ".log");
    ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + out.string() +
                        kDeterministic + " --max_frames 12 --set odometry.frontend_thread=" +
                        (frontend_thread ? "true" : "false"),
                    log),
              0)
        << Slurp(log);
    trajectories[frontend_thread] = Slurp(out / "trajectory.txt");
    const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
    EXPECT_EQ(summary["frontend_thread"], frontend_thread);
    EXPECT_EQ(summary["tracked"], 12);
    EXPECT_GT(summary["ms_median"]["detection"].get<double>(), 0.0);
  }
  EXPECT_EQ(trajectories[1], trajectories[0]);
}

// output.keyframe_map_error: every keyframe's map against the rendered depth. From the GT depth
// the scale is 1 and the error is that of the filter under tracked poses; monocularly the scale is
// free and comes out as whatever the random initial map gave.
TEST(RunCommandTest, KeyframeMapsAreEvaluatedAgainstTheDepthImages) {
  const char* const kMapError = " --set output.keyframe_map_error=true";
  const fs::path out = TestRoot() / "run_maps";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + out.string() +
                      kDeterministic + kMapError + " --set odometry.init_depth_idepth_var=0.0001",
                  TestRoot() / "run_maps.log"),
            0)
      << Slurp(TestRoot() / "run_maps.log");
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  const std::vector<std::vector<std::string>> rows = CsvRows(out / "keyframe_maps.csv");
  // Every keyframe, the last one at the end of the run included.
  ASSERT_EQ(static_cast<int>(rows.size()), summary["keyframes"].get<int>());
  for (const std::vector<std::string>& row : rows) {
    ASSERT_EQ(row.size(), 18u);
    std::printf("keyframe %s (frame %s): scale %s, %s px, median rel. err %s, median NEES %s\n",
                row[0].c_str(), row[1].c_str(), row[3].c_str(), row[4].c_str(), row[5].c_str(),
                row[7].c_str());
    EXPECT_NEAR(std::stod(row[3]), 1.0, 0.02) << "scale of keyframe " << row[0];
    EXPECT_GT(std::stoi(row[4]), 1000) << "evaluated pixels of keyframe " << row[0];
    EXPECT_LT(std::stod(row[5]), 0.03) << "median relative error of keyframe " << row[0];
  }
  const nlohmann::json& maps = summary["keyframe_maps"];
  ASSERT_TRUE(maps.is_object());
  EXPECT_EQ(maps["keyframes"].get<size_t>(), rows.size());
  EXPECT_NEAR(maps["scale_median"].get<double>(), 1.0, 0.02);

  const fs::path mono = TestRoot() / "run_maps_mono";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + mono.string() +
                      kDeterministic + kMapError + " --max_frames 12",
                  TestRoot() / "run_maps_mono.log"),
            0);
  const std::vector<std::vector<std::string>> mono_rows = CsvRows(mono / "keyframe_maps.csv");
  ASSERT_FALSE(mono_rows.empty());
  EXPECT_GT(std::stod(mono_rows[0][3]), 0.0);

  // A dataset without depth images: the run is not affected, and says so.
  const fs::path no_depth = TestRoot() / "no_depth";
  fs::remove_all(no_depth);
  fs::copy(SequenceDir(), no_depth, fs::copy_options::recursive);
  fs::remove(no_depth / "depth.txt");
  const fs::path out_no_depth = TestRoot() / "run_maps_no_depth";
  ASSERT_EQ(Pldvo("run --dataset " + no_depth.string() + " --out " + out_no_depth.string() +
                      kDeterministic + kMapError + " --max_frames 12",
                  TestRoot() / "run_maps_no_depth.log"),
            0);
  EXPECT_NE(Slurp(TestRoot() / "run_maps_no_depth.log").find("no depth image for frame 0"),
            std::string::npos)
      << Slurp(TestRoot() / "run_maps_no_depth.log");
  EXPECT_TRUE(
      nlohmann::json::parse(Slurp(out_no_depth / "summary.json"))["keyframe_maps"].is_null());
  EXPECT_FALSE(fs::exists(out_no_depth / "keyframe_maps.csv"));
}

// odometry.bootstrap_passes: the passes re-run the first keyframe's frames (pass 1 is the plain
// run's start, so it stops once the plain run's second keyframe has begun) and keep its map, the
// run then tracks every frame; a failed pass falls back to the random map; combinations that make
// no sense are config errors.
TEST(RunCommandTest, BootstrapRefinementRerunsTheFirstKeyframeFrames) {
  // A keyframe at least every 8 frames keeps the passes short (CI budget).
  const std::string kFramesFlag = " --max_frames 16 --set keyframes.max_frames=8";
  const fs::path plain = TestRoot() / "run_bootstrap_plain";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + plain.string() +
                      kDeterministic + kFramesFlag,
                  TestRoot() / "run_bootstrap_plain.log"),
            0);
  int second_keyframe = -1;
  for (const std::vector<std::string>& row : CsvRows(plain / "timing.csv")) {
    if (row[2] == "keyframe" && row[3] == "1") second_keyframe = std::stoi(row[0]);
  }
  ASSERT_GT(second_keyframe, 0);

  const fs::path refined = TestRoot() / "run_bootstrap";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + refined.string() +
                      kDeterministic + kFramesFlag + " --set odometry.bootstrap_passes=3",
                  TestRoot() / "run_bootstrap.log"),
            0)
      << Slurp(TestRoot() / "run_bootstrap.log");
  const nlohmann::json summary = nlohmann::json::parse(Slurp(refined / "summary.json"));
  const nlohmann::json& bootstrap = summary["bootstrap"];
  ASSERT_TRUE(bootstrap.is_object()) << summary.dump();
  ASSERT_EQ(bootstrap["frames"].size(), 2u);
  ASSERT_EQ(bootstrap["points"].size(), 2u);
  std::printf("second keyframe at frame %d; passes: frames %s, points %s\n", second_keyframe,
              bootstrap["frames"].dump().c_str(), bootstrap["points"].dump().c_str());
  // Pass 1 ends when the first keyframe's map is final: with or just after the second keyframe.
  EXPECT_GE(bootstrap["frames"][0].get<int>(), second_keyframe + 1);
  EXPECT_LE(bootstrap["frames"][0].get<int>(), second_keyframe + 2);
  EXPECT_GT(bootstrap["frames"][1].get<int>(), 1);
  for (const nlohmann::json& points : bootstrap["points"]) EXPECT_GT(points.get<int>(), 1000);
  EXPECT_EQ(summary["tracked"].get<int>(), 16);
  EXPECT_TRUE(nlohmann::json::parse(Slurp(plain / "summary.json"))["bootstrap"].is_null());

  // One frame: the pass's map has no stereo observation, so the run starts from the random map
  // and says so.
  const fs::path one = TestRoot() / "run_bootstrap_one_frame";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + one.string() +
                      kDeterministic + " --max_frames 1 --set odometry.bootstrap_passes=2",
                  TestRoot() / "run_bootstrap_one_frame.log"),
            0)
      << Slurp(TestRoot() / "run_bootstrap_one_frame.log");
  EXPECT_NE(Slurp(TestRoot() / "run_bootstrap_one_frame.log").find("bootstrap refinement failed"),
            std::string::npos)
      << Slurp(TestRoot() / "run_bootstrap_one_frame.log");
  EXPECT_TRUE(nlohmann::json::parse(Slurp(one / "summary.json"))["bootstrap"].is_null());

  for (const std::string& bad :
       {std::string(" --set odometry.bootstrap_passes=0"),
        std::string(
            " --set odometry.bootstrap_passes=2 --set odometry.init_depth_idepth_var=0.0001"),
        std::string(" --set odometry.bootstrap_idepth_var=0")}) {
    const fs::path log = TestRoot() / "run_bootstrap_bad.log";
    EXPECT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " +
                        (TestRoot() / "run_bootstrap_bad").string() + bad,
                    log),
              2)
        << bad;
    EXPECT_NE(Slurp(log).find("bootstrap_"), std::string::npos) << Slurp(log);
  }
}

// odometry.two_view_bootstrap: the run reports the second view and tracks every frame from frame
// 0's bootstrapped map (gates lowered to 0.3 deg, 1 px and a 30 deg direction uncertainty without
// the stability check: this sequence moves forward and reaches no default in 36 frames;
// TwoViewBootstrapTest checks the geometry); when the bootstrap
// fails (two frames, no parallax) the run starts from the random map and says why; combinations
// with the other starts are config errors.
TEST(RunCommandTest, TwoViewBootstrapStartsTheRunOrFallsBack) {
  const std::string kFlags = kDeterministic + std::string(" --max_frames 36");
  const fs::path run = TestRoot() / "run_two_view";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + run.string() + kFlags +
                      " --set odometry.two_view_bootstrap=true"
                      " --set odometry.two_view_min_parallax_deg=0.3"
                      " --set odometry.two_view_min_rotation_free_parallax_px=1"
                      " --set odometry.two_view_max_direction_std_deg=30"
                      " --set odometry.two_view_stable_frames=1",
                  TestRoot() / "run_two_view.log"),
            0)
      << Slurp(TestRoot() / "run_two_view.log");
  const nlohmann::json summary = nlohmann::json::parse(Slurp(run / "summary.json"));
  const nlohmann::json& two_view = summary["two_view_bootstrap"];
  ASSERT_TRUE(two_view.is_object()) << Slurp(TestRoot() / "run_two_view.log");
  std::printf("two-view bootstrap: %s\n", two_view.dump().c_str());
  EXPECT_GT(two_view["second_view"].get<int>(), 0);
  EXPECT_LT(two_view["second_view"].get<int>(), 36);
  EXPECT_GE(two_view["parallax_deg"].get<double>(), 0.3);
  EXPECT_GE(two_view["rotation_free_parallax_px"].get<double>(), 1.0);
  EXPECT_LE(two_view["direction_std_deg"].get<double>(), 30.0);
  EXPECT_GT(two_view["photometric_points"].get<int>(), 0);
  EXPECT_GT(two_view["points"].get<int>(), 1000);
  EXPECT_EQ(summary["tracked"].get<int>(), 36);

  const fs::path two = TestRoot() / "run_two_view_two_frames";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + two.string() +
                      kDeterministic + " --max_frames 2 --set odometry.two_view_bootstrap=true",
                  TestRoot() / "run_two_view_two_frames.log"),
            0);
  const std::string log = Slurp(TestRoot() / "run_two_view_two_frames.log");
  EXPECT_NE(log.find("parallax"), std::string::npos) << log;
  EXPECT_NE(log.find("starts from the random map"), std::string::npos) << log;
  EXPECT_TRUE(nlohmann::json::parse(Slurp(two / "summary.json"))["two_view_bootstrap"].is_null());

  // A refinement or a depth start asked for replaces the two-view bootstrap (it does not run, and
  // its summary entry stays null).
  for (const std::string& other : {std::string(" --set odometry.bootstrap_passes=2"),
                                   std::string(" --set odometry.init_depth_idepth_var=0.0001")}) {
    const fs::path other_run = TestRoot() / "run_two_view_replaced";
    const fs::path other_log = TestRoot() / "run_two_view_replaced.log";
    ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + other_run.string() +
                        kDeterministic + " --max_frames 12 --set odometry.two_view_bootstrap=true" +
                        other,
                    other_log),
              0)
        << other << Slurp(other_log);
    EXPECT_TRUE(
        nlohmann::json::parse(Slurp(other_run / "summary.json"))["two_view_bootstrap"].is_null())
        << other;
  }
  const fs::path bad_log = TestRoot() / "run_two_view_bad.log";
  EXPECT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " +
                      (TestRoot() / "run_two_view_bad").string() +
                      " --set odometry.two_view_min_parallax_deg=0",
                  bad_log),
            2);
  EXPECT_NE(Slurp(bad_log).find("two_view"), std::string::npos) << Slurp(bad_log);
}

// odometry.random_start_candidates: the run tries three random initial maps over the first
// frames, scores each by the fit of its tracked frames, and starts from the best: the chosen
// candidate's scores are the means that a plain run from its seed reports for the same frames,
// and the run is that plain run, pose for pose.
TEST(RunCommandTest, RandomStartChoosesTheBestFittingInitialMap) {
  const std::string kFlags = kDeterministic + std::string(" --max_frames 16");
  const fs::path chosen_run = TestRoot() / "run_random_start";
  ASSERT_EQ(
      Pldvo("run --dataset " + SequenceDir().string() + " --out " + chosen_run.string() + kFlags +
                " --set odometry.random_start_candidates=3"
                " --set odometry.random_start_frames=10",
            TestRoot() / "run_random_start.log"),
      0)
      << Slurp(TestRoot() / "run_random_start.log");
  const nlohmann::json summary = nlohmann::json::parse(Slurp(chosen_run / "summary.json"));
  ASSERT_TRUE(summary["two_view_bootstrap"].is_null());  // the start this choice is for
  const nlohmann::json& choice = summary["random_start"];
  ASSERT_TRUE(choice.is_object()) << summary.dump();
  std::printf("random start: %s\n", choice.dump().c_str());
  EXPECT_EQ(choice["frames"].get<int>(), 10);
  // The two-view start fails at its parallax gates here: no corners to check against.
  EXPECT_EQ(choice["score"], "correlation");
  ASSERT_EQ(choice["candidates"].size(), 3u);
  const nlohmann::json* best = nullptr;
  for (size_t c = 0; c < 3; ++c) {
    const nlohmann::json& candidate = choice["candidates"][c];
    EXPECT_EQ(candidate["init_seed"].get<int>(), 1 + 1000 * static_cast<int>(c));
    EXPECT_EQ(candidate["untracked"].get<int>(), 0);
    EXPECT_GT(candidate["mean_correlation"].get<double>(), 0.0);
    EXPECT_GT(candidate["mean_rms"].get<double>(), 0.0);
    if (best == nullptr || candidate["mean_correlation"] > (*best)["mean_correlation"]) {
      best = &candidate;
    }
  }
  EXPECT_EQ(choice["init_seed"], (*best)["init_seed"]);

  const int seed = choice["init_seed"].get<int>();
  const fs::path plain = TestRoot() / "run_random_start_plain";
  ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + plain.string() + kFlags +
                      " --set mapping.init_seed=" + std::to_string(seed),
                  TestRoot() / "run_random_start_plain.log"),
            0);
  EXPECT_TRUE(nlohmann::json::parse(Slurp(plain / "summary.json"))["random_start"].is_null());
  EXPECT_EQ(Slurp(plain / "trajectory.txt"), Slurp(chosen_run / "trajectory.txt"));
  double rms_sum = 0.0, correlation_sum = 0.0;
  int tracked = 0;
  for (const std::vector<std::string>& row : CsvRows(plain / "timing.csv")) {
    const int index = std::stoi(row[0]);
    if (index < 1 || index >= 10) continue;
    ASSERT_TRUE(row[2] == "tracked" || row[2] == "keyframe") << row[2];
    rms_sum += std::stod(row[10]);
    correlation_sum += std::stod(row[12]);
    ++tracked;
  }
  ASSERT_EQ(tracked, 9);
  EXPECT_NEAR((*best)["mean_rms"].get<double>(), rms_sum / tracked, 1e-5);
  EXPECT_NEAR((*best)["mean_correlation"].get<double>(), correlation_sum / tracked, 1e-5);

  const fs::path bad_log = TestRoot() / "run_random_start_bad.log";
  EXPECT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " +
                      (TestRoot() / "run_random_start_bad").string() +
                      " --set odometry.random_start_candidates=0",
                  bad_log),
            2);
  EXPECT_NE(Slurp(bad_log).find("random_start_candidates"), std::string::npos) << Slurp(bad_log);
}

// Where the two-view start fails only at its direction gate (forced here by stronger corners
// and no rotation-free gate, as in TwoViewBootstrapTest.NearRotationIsRejectedByEitherGate),
// the random start's candidates are ranked by the epipolar error of its tracked corners; with
// odometry.random_start_corner_check=false by the correlation, the errors still reported.
TEST(RunCommandTest, RandomStartChecksTheCandidatesAgainstTheTrackedCorners) {
  const std::string kFlags = kDeterministic + std::string(" --max_frames 16") +
                             " --set odometry.random_start_candidates=3"
                             " --set odometry.random_start_frames=10"
                             " --set odometry.two_view_corner_quality=0.01"
                             " --set odometry.two_view_corner_min_distance_px=7"
                             " --set odometry.two_view_min_rotation_free_parallax_px=0"
                             " --set odometry.two_view_min_parallax_deg=0.2";
  for (const bool check : {true, false}) {
    SCOPED_TRACE(check ? "corner check" : "no corner check");
    const std::string name = std::string("run_random_start_corners_") + (check ? "on" : "off");
    const fs::path out = TestRoot() / name;
    const fs::path log = TestRoot() / (name + ".log");
    ASSERT_EQ(Pldvo("run --dataset " + SequenceDir().string() + " --out " + out.string() + kFlags +
                        " --set odometry.random_start_corner_check=" + (check ? "true" : "false"),
                    log),
              0)
        << Slurp(log);
    EXPECT_NE(Slurp(log).find("fixes the translation direction"), std::string::npos) << Slurp(log);
    const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
    const nlohmann::json& choice = summary["random_start"];
    ASSERT_TRUE(choice.is_object()) << summary.dump();
    std::printf("random start: %s\n", choice.dump().c_str());
    EXPECT_EQ(choice["score"], check ? "corners" : "correlation");
    ASSERT_EQ(choice["candidates"].size(), 3u);
    const nlohmann::json* best = nullptr;
    for (const nlohmann::json& candidate : choice["candidates"]) {
      ASSERT_EQ(candidate["untracked"].get<int>(), 0);
      ASSERT_TRUE(candidate["corner_error_px"].is_number()) << candidate.dump();
      EXPECT_GT(candidate["corner_error_px"].get<double>(), 0.0);
      EXPECT_LT(candidate["corner_error_px"].get<double>(), 5.0);
      const bool better =
          best == nullptr || (check ? candidate["corner_error_px"] < (*best)["corner_error_px"]
                                    : candidate["mean_correlation"] > (*best)["mean_correlation"]);
      if (better) best = &candidate;
    }
    EXPECT_EQ(choice["init_seed"], (*best)["init_seed"]);
  }
}

TEST(RunCommandTest, UnknownConfigKeyIsAnError) {
  // The config is checked before the dataset is opened: no dataset needed.
  const fs::path log = TestRoot() / "run_bad_key.log";
  EXPECT_EQ(Pldvo("run --dataset " + (TestRoot() / "no_such_dataset").string() + " --out " +
                      (TestRoot() / "run_bad_key").string() + " --set keyframes.min_overlapp=0.5",
                  log),
            2);
  EXPECT_NE(Slurp(log).find("keyframes.min_overlapp"), std::string::npos) << Slurp(log);
  EXPECT_FALSE(fs::exists(TestRoot() / "run_bad_key" / "trajectory.txt"));
}

TEST(AblateCommandTest, TinyGridWritesTablesAndPlot) {
  const fs::path configs = fs::path(PLDVO_SOURCE_DIR) / "experiments" / "configs";
  const fs::path out = TestRoot() / "ablate";
  const fs::path log = TestRoot() / "ablate.log";
  ASSERT_EQ(
      Pldvo("ablate --configs " + (configs / "sdvo.yaml").string() + "," +
                (configs / "points_lines.yaml").string() + " --datasets " + SequenceDir().string() +
                " --out " + out.string() + " --jobs 2" + kDeterministic,
            log),
      0)
      << Slurp(log);
  // results.csv: header + one row per pair, both evaluated.
  EXPECT_EQ(CountLines(out / "results.csv", false), 3);
  const std::string csv = Slurp(out / "results.csv");
  EXPECT_NE(csv.find("lowtex,sdvo,ok,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("lowtex,points_lines,ok,"), std::string::npos) << csv;
  EXPECT_EQ(csv.rfind("dataset,config,status,frames,tracked,keyframes,lost_events,rpe_cm_s,"
                      "rpe_deg_s,ate_m,coverage,scale_drift,",
                      0),
            0u)
      << csv;
  // The scale segments, the motion direction error, the rotation ratio, the windowed BA's
  // re-anchored figures and the still estimate's RPE close the header (appended: scripts read the
  // columns by position), and
  // neither run of this short sequence re-initialises.
  EXPECT_NE(csv.find(",dir,scale_segments,motion_direction_error_deg_median,motion_rotation_ratio,"
                     "reanchored_rpe_cm_s,reanchored_rpe_deg_s,keyframes_ate_m_ba,"
                     "rpe_cm_s_still\n"),
            std::string::npos)
      << csv;
  EXPECT_NE(csv.find("/lowtex__sdvo,1,"), std::string::npos) << csv;
  // results.md: the RPE table with one row for the sequence and a column per config.
  const std::string md = Slurp(out / "results.md");
  EXPECT_NE(md.find("| sequence | sdvo | points_lines |"), std::string::npos) << md;
  EXPECT_NE(md.find("| lowtex |"), std::string::npos) << md;
  EXPECT_NE(md.find("### RPE translation of an estimate that never moves"), std::string::npos)
      << md;
  EXPECT_NE(md.find("### Scale drift"), std::string::npos) << md;
  EXPECT_NE(md.find("### Scale segments"), std::string::npos) << md;
  EXPECT_NE(md.find("### Translation direction error"), std::string::npos) << md;
  // Inline mapping runs on the tracking thread, and the timing table says so.
  EXPECT_NE(md.find("### Median tracking-thread time per frame (ms; mapping inline, included)"),
            std::string::npos)
      << md;
  // The trajectory plot: an SVG with the ground truth and one polyline per config.
  const std::string svg = Slurp(out / "trajectories_lowtex.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  size_t polylines = 0;
  for (size_t pos = svg.find("<polyline"); pos != std::string::npos;
       pos = svg.find("<polyline", pos + 1)) {
    ++polylines;
  }
  EXPECT_EQ(polylines, 3u);
  // A grid with a missing dataset: that run fails and shows as X, the command exits 1.
  const fs::path out2 = TestRoot() / "ablate_missing";
  EXPECT_EQ(Pldvo("ablate --configs " + (configs / "sdvo.yaml").string() + " --datasets " +
                      (TestRoot() / "no_such_dataset").string() + " --out " + out2.string(),
                  TestRoot() / "ablate_missing.log"),
            1);
  EXPECT_NE(Slurp(out2 / "results.md").find("| no_such_dataset | X |"), std::string::npos)
      << Slurp(out2 / "results.md");
  EXPECT_NE(Slurp(out2 / "results.md").find("### Median tracking-thread time per frame (ms)\n"),
            std::string::npos)
      << Slurp(out2 / "results.md");
}

TEST(AblateCommandTest, RepeatsRunEachPairWithItsOwnInitSeed) {
  // Monocular runs from a random initial map: --repeats 2 runs the pair with mapping.init_seed 1
  // and 2 and the table gives the median and [min, max]; --run_max_frames caps every run.
  const fs::path config = fs::path(PLDVO_SOURCE_DIR) / "experiments" / "configs" / "sdvo.yaml";
  const fs::path out = TestRoot() / "ablate_repeats";
  const fs::path log = TestRoot() / "ablate_repeats.log";
  ASSERT_EQ(Pldvo("ablate --configs " + config.string() + " --datasets " + SequenceDir().string() +
                      " --out " + out.string() + " --repeats 2 --jobs 2 --run_max_frames 34" +
                      kDeterministic,
                  log),
            0)
      << Slurp(log);
  EXPECT_EQ(CountLines(out / "results.csv", false), 3);
  for (const int seed : {1, 2}) {
    const fs::path run = out / "runs" / ("lowtex__sdvo__seed" + std::to_string(seed));
    const std::string effective = Slurp(run / "config.yaml");
    EXPECT_NE(effective.find("init_seed: " + std::to_string(seed)), std::string::npos) << effective;
    ASSERT_TRUE(fs::exists(run / "summary.json"));
    // --run_max_frames reaches the runs as --max_frames.
    EXPECT_EQ(nlohmann::json::parse(Slurp(run / "summary.json"))["frames"], 34);
  }
  const std::string md = Slurp(out / "results.md");
  EXPECT_NE(md.find("median and [min, max] over 2 runs"), std::string::npos) << md;
  EXPECT_NE(md.find("| lowtex | "), std::string::npos) << md;
  EXPECT_NE(md.find("] |"), std::string::npos) << md;
  EXPECT_EQ(Pldvo("ablate --configs " + config.string() + " --datasets " + SequenceDir().string() +
                      " --out " + out.string() + " --repeats 0",
                  log),
            2);
}

// A grid split into shards that run one after another on a shared output folder, then
// `--collect`, gives the results of one unsharded run (deterministic mode): results.csv equal
// field by field except the timing columns (wall-clock) and the run folder (another OUT), and
// results.json's non-timing statistics equal. Grid: 2 configs x 1 sequence x 2 repeats; under the
// sanitizers (docs/reliability.md) points_lines only on the first 12 frames (RPE over 0.2 s), the
// same bookkeeping on half the runs.
TEST(AblateCommandTest, ShardsThenCollectGiveTheResultsOfOneRun) {
  const fs::path configs = fs::path(PLDVO_SOURCE_DIR) / "experiments" / "configs";
#ifdef PLDVO_SANITIZE
  const std::string config_list = (configs / "points_lines.yaml").string();
  const size_t num_configs = 1;
  const std::string frames = " --run_max_frames 12 --set evaluation.rpe_delta=0.2";
#else
  const std::string config_list =
      (configs / "sdvo.yaml").string() + "," + (configs / "points_lines.yaml").string();
  const size_t num_configs = 2;
  const std::string frames;
#endif
  const size_t num_runs = 2 * num_configs;
  const std::string grid = " --configs " + config_list + " --datasets " + SequenceDir().string() +
                           " --repeats 2" + kDeterministic + frames;
  const fs::path one = TestRoot() / "ablate_one", sharded = TestRoot() / "ablate_sharded";
  const fs::path log = TestRoot() / "ablate_shards.log";
  ASSERT_EQ(Pldvo("ablate" + grid + " --out " + one.string() + " --jobs 2", log), 0) << Slurp(log);
  // Collecting before every shard ran reports the missing runs.
  ASSERT_EQ(Pldvo("ablate" + grid + " --out " + sharded.string() + " --shard 0/2", log), 0)
      << Slurp(log);
  EXPECT_EQ(Pldvo("ablate" + grid + " --out " + sharded.string() + " --collect", log), 1);
  const std::string missing = std::to_string(num_runs / 2) + " of " + std::to_string(num_runs) +
                              " runs have no summary.json";
  EXPECT_NE(Slurp(log).find(missing), std::string::npos) << Slurp(log);
  ASSERT_EQ(
      Pldvo("ablate" + grid + " --out " + sharded.string() + " --shard 1/2 --skip_existing", log),
      0)
      << Slurp(log);
  fs::remove(sharded / "results.csv");
  fs::remove(sharded / "results.json");
  ASSERT_EQ(Pldvo("ablate" + grid + " --out " + sharded.string() + " --collect", log), 0)
      << Slurp(log);

  const auto expected = CsvRows(one / "results.csv"), actual = CsvRows(sharded / "results.csv");
  ASSERT_EQ(expected.size(), num_runs);
  ASSERT_EQ(actual.size(), expected.size());
  // Columns: ..., 12 ms_median_tracking_thread, 13 ms_median_total, 14 init_seed, 15 dir,
  // 16 scale_segments, 17 motion_direction_error_deg_median, 18 motion_rotation_ratio,
  // 19-21 re-anchored RPE, rotation RPE, keyframe ATE, 22 rpe_cm_s_still: all but the times and
  // the run folder must agree.
  for (size_t row = 0; row < expected.size(); ++row) {
    ASSERT_EQ(actual[row].size(), 23u);
    ASSERT_EQ(expected[row].size(), 23u);
    EXPECT_EQ(expected[row][2], "ok") << "row " << row;
    // Without the windowed BA the re-anchored RPE is trajectory.txt's, the keyframe ATE empty.
    EXPECT_EQ(expected[row][19], expected[row][7]) << "row " << row;
    EXPECT_EQ(expected[row][21], "") << "row " << row;
    // The still estimate's RPE, the ground truth's own motion per second: these short renders
    // are tracked, so each run's RPE is below it.
    EXPECT_LT(std::stod(expected[row][7]), std::stod(expected[row][22])) << "row " << row;
    for (size_t column = 0; column < 23; ++column) {
      if (column == 12 || column == 13 || column == 15) continue;
      EXPECT_EQ(actual[row][column], expected[row][column])
          << "row " << row << " column " << column;
    }
  }
  const nlohmann::json a = nlohmann::json::parse(Slurp(one / "results.json"));
  const nlohmann::json b = nlohmann::json::parse(Slurp(sharded / "results.json"));
  ASSERT_EQ(a["cells"].size(), num_configs);
  ASSERT_EQ(b["cells"].size(), num_configs);
  for (size_t cell = 0; cell < num_configs; ++cell) {
    for (const char* key : {"dataset", "config", "runs", "ok", "failed", "not_run", "lost_events",
                            "rpe_cm_s", "rpe_deg_s", "ate_m", "scale_drift"}) {
      EXPECT_EQ(a["cells"][cell][key], b["cells"][cell][key]) << "cell " << cell << " " << key;
    }
    EXPECT_EQ(b["cells"][cell]["ok"], 2);
    EXPECT_TRUE(b["cells"][cell]["ms_tracking_thread"].is_object());
  }
}

TEST(BasinCommandTest, FrontendLinesTrackSmallGapsToTheTruth) {
  // The odometry's reference from GT depth with the real frontend's matches: at gaps 1-4 the
  // photometric and the points-and-lines problems converge to the true pose from the identity
  // (docs/tracking.md, "The frontend's lines from a correct map"), the matches are judged by
  // depth, and the oracle needs basin.lines=frontend.
  const fs::path csv = TestRoot() / "basin_frontend.csv";
  const fs::path log = TestRoot() / "basin_frontend.log";
  const std::string pairs =
      "basin --set basin.lines=frontend --set basin.frames=60 --set basin.pairs=4 "
      "--set basin.max_gap=4";
  ASSERT_EQ(Pldvo(pairs + " --basin_csv " + csv.string(), log), 0) << Slurp(log);
  const std::string output = Slurp(log);
  EXPECT_NE(output.find("Matches judged by depth: "), std::string::npos) << output;
  const std::vector<std::vector<std::string>> rows = CsvRows(csv);
  ASSERT_EQ(rows.size(), 12u);  // 4 pairs x 3 modes
  for (const std::vector<std::string>& row : rows) {
    ASSERT_EQ(row.size(), 12u);
    if (row[5] == "lines") continue;  // lines alone need not converge at these gaps
    EXPECT_EQ(row[8], "1") << row[0] << " -> " << row[1] << " " << row[5];
    EXPECT_LT(std::stod(row[6]), 0.005) << row[0] << " -> " << row[1] << " " << row[5];
  }
  // The oracle on one pair (it runs; the sanitizers' CI budget, docs/reliability.md).
  EXPECT_EQ(Pldvo(pairs + " --set basin.pairs=1 --set basin.drop_wrong_matches=true", log), 0)
      << Slurp(log);
  EXPECT_EQ(Pldvo("basin --set basin.drop_wrong_matches=true", log), 1);
  EXPECT_NE(Slurp(log).find("drop_wrong_matches needs lines=frontend"), std::string::npos)
      << Slurp(log);
}

}  // namespace
}  // namespace pldvo
