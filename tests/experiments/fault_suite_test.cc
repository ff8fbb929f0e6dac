// The `pldvo run` fault suite (docs/reliability.md): one test per input or output fault, end to
// end through the real binary (PLDVO_BINARY) on a small synthetic sequence in the TUM layout
// (320x240), with the deterministic single-thread mapping. The policy checked:
//   - a frame that cannot be used (missing, truncated or undecodable PNG, wrong size) is
//     reported with its file, marked `failed` in timing.csv and skipped; the run exits 0;
//   - a frame without texture (all black, all white, 30 frames of a blank wall) or without the
//     scene (uniform noise) is processed, marked lost / reinitialized, and tracking resumes
//     afterwards; the run exits 0;
//   - a fault in a text input (rgb.txt timestamps duplicated or decreasing, NaN in the ground
//     truth, an unknown camera model) is fatal at start-up with exit code 1, naming file and line
//     (camera.yaml: file and key), before any frame is processed;
//   - a camera that fits no frame (no frame tracked) and an unwritable output exit 1.
// Every pldvo call runs under `timeout`, so a hang fails its test instead of stalling ctest.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/trajectory_io.h"
#include "experiments/synthetic/synthetic_sequence.h"
#include "tests/experiments/test_folder.h"
#include "tests/render_cache.h"
#include "tests/small_lowtex_options.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;

// Frames of the short sequence; the fault is at frame kFault, with frames before it to
// initialise and after it to recover. The blank-wall sequence: 30 blank frames from kWallStart,
// then kWallAfter frames of the scene. Under the sanitizers (about 10x slower) the same faults on
// fewer frames, rendered without supersampling, and one noise draw instead of three.
#ifdef PLDVO_SANITIZE
constexpr int kFrames = 10;
constexpr int kFault = 5;
constexpr int kWallStart = 5;
constexpr int kWallAfter = 10;
constexpr int kSupersampling = 1;
constexpr int kNoiseDraws = 1;
#else
constexpr int kFrames = 24;
constexpr int kFault = 12;
constexpr int kWallStart = 10;
constexpr int kWallAfter = 25;
constexpr int kSupersampling = 4;  // the generator's default
constexpr int kNoiseDraws = 3;
#endif
constexpr int kWallFrames = 30;
// Seconds before a pldvo call counts as hung (a Release run of these takes 1 to 4 s).
constexpr int kHangSeconds = 300;

using test::Slurp;
using test::TestRoot;

// A lowtex synthetic sequence of `frames` frames in TUM layout, written once per ctest run and
// length (tests/render_cache.h); returns its folder, which tests damage only through CopyOf.
fs::path Sequence(int frames) {
  synthetic::SynthOptions options = test::SmallLowtexOptions(frames);
  options.supersampling = kSupersampling;
  return test::SequenceFolderForTest(options, TestRoot() / ("lowtex_" + std::to_string(frames)));
}

// A private copy of a sequence that a test may damage.
fs::path CopyOf(const fs::path& sequence, const std::string& name) {
  const fs::path dataset = TestRoot() / name;
  fs::remove_all(dataset);
  fs::copy(sequence, dataset, fs::copy_options::recursive);
  return dataset;
}

// The image files of a TUM-layout sequence, in frame order.
std::vector<fs::path> Images(const fs::path& dataset) {
  std::vector<fs::path> images;
  for (const auto& entry : fs::directory_iterator(dataset / "rgb")) images.push_back(entry.path());
  std::sort(images.begin(), images.end());
  return images;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::trunc | std::ios::binary);
  file << text;
}

// The status column of timing.csv, one entry per row (frame order).
std::vector<std::string> Statuses(const fs::path& out) {
  std::ifstream file(out / "timing.csv");
  std::string line;
  std::getline(file, line);  // header
  std::vector<std::string> statuses;
  while (std::getline(file, line)) {
    std::stringstream fields(line);
    std::string index, timestamp, status;
    std::getline(fields, index, ',');
    std::getline(fields, timestamp, ',');
    std::getline(fields, status, ',');
    statuses.push_back(status);
  }
  return statuses;
}

bool IsTrackedStatus(const std::string& status) {
  return status == "tracked" || status == "keyframe" || status == "recovered";
}

struct RunResult {
  int exit_code = -1;  // 124: killed by `timeout` (hung)
  std::string log;     // stdout and stderr
};

// Runs `pldvo run --dataset DATASET --out OUT` (deterministic mapping, one random start) plus
// `extra`, under `timeout`; OUT is TestRoot()/name.
RunResult RunPldvo(const fs::path& dataset, const std::string& name,
                   const std::string& extra = "") {
  std::string log_name = name + ".log";
  std::replace(log_name.begin(), log_name.end(), '/', '_');
  const fs::path log = TestRoot() / log_name;
  const std::string command =
      "timeout -k 5 " + std::to_string(kHangSeconds) + " " + std::string(PLDVO_BINARY) +
      " run --dataset " + dataset.string() + " --out " + (TestRoot() / name).string() +
      " --set odometry.parallel_mapping=false --set odometry.random_start_candidates=1 " + extra +
      " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.log = Slurp(log);
  return result;
}

// A skipped frame: exit 0, the message names the frame and its file, the frame is `failed` in
// timing.csv and summary.json, and every other frame is tracked and in trajectory.txt.
void ExpectFrameSkipped(const RunResult& run, const fs::path& out, const fs::path& file,
                        const std::string& reason) {
  ASSERT_EQ(run.exit_code, 0) << run.log;
  EXPECT_NE(run.log.find("frame " + std::to_string(kFault) + " skipped"), std::string::npos)
      << run.log;
  EXPECT_NE(run.log.find(file.string() + ": " + reason), std::string::npos) << run.log;
  const std::vector<std::string> statuses = Statuses(out);
  ASSERT_EQ(statuses.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    if (i == kFault) {
      EXPECT_EQ(statuses[i], "failed");
    } else {
      EXPECT_TRUE(IsTrackedStatus(statuses[i])) << "frame " << i << ": " << statuses[i];
    }
  }
  const Trajectory trajectory = ReadTrajectoryTum((out / "trajectory.txt").string());
  EXPECT_EQ(trajectory.size(), static_cast<size_t>(kFrames - 1));
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  EXPECT_EQ(summary["failed_frames"], 1);
  EXPECT_EQ(summary["tracked"], kFrames - 1);
  EXPECT_EQ(summary["lost_events"], 1);
}

// A fatal start-up fault: exit 1, the message contains `where` (file and line or key), and no
// frame was processed (no timing.csv rows, no trajectory).
void ExpectFatalAtStart(const RunResult& run, const fs::path& out, const std::string& where) {
  EXPECT_EQ(run.exit_code, 1) << run.log;
  EXPECT_NE(run.log.find(where), std::string::npos) << "expected '" << where << "' in\n" << run.log;
  EXPECT_FALSE(fs::exists(out / "trajectory.txt"));
  EXPECT_FALSE(fs::exists(out / "summary.json"));
}

// `frame` replaces frame kFault: it shows nothing of the scene, so it cannot be tracked. It is
// marked lost (not failed: it loaded), and the next frame tracks again against the keyframe.
void ExpectReplacedFrameLost(const cv::Mat& frame, const std::string& name) {
  const fs::path dataset = CopyOf(Sequence(kFrames), name);
  const fs::path image = Images(dataset).at(kFault);
  ASSERT_TRUE(cv::imwrite(image.string(), frame));
  const RunResult run = RunPldvo(dataset, "run_" + name);
  const fs::path out = TestRoot() / ("run_" + name);
  ASSERT_EQ(run.exit_code, 0) << run.log;
  const std::vector<std::string> statuses = Statuses(out);
  ASSERT_EQ(statuses.size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(statuses[kFault], "lost");
  for (int i = 0; i < kFrames; ++i) {
    if (i != kFault) {
      EXPECT_TRUE(IsTrackedStatus(statuses[i])) << "frame " << i << ": " << statuses[i];
    }
  }
  EXPECT_EQ(statuses[kFault + 1], "recovered");
  const Trajectory trajectory = ReadTrajectoryTum((out / "trajectory.txt").string());
  EXPECT_EQ(trajectory.size(), static_cast<size_t>(kFrames - 1));
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  EXPECT_EQ(summary["failed_frames"], 0);
  EXPECT_EQ(summary["lost_frames"], 1);
  EXPECT_EQ(summary["lost_events"], 1);
}

TEST(FaultSuiteTest, MissingImageIsSkipped) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "missing");
  const fs::path image = Images(dataset).at(kFault);
  fs::remove(image);
  ExpectFrameSkipped(RunPldvo(dataset, "run_missing"), TestRoot() / "run_missing", image,
                     "image file not found");
}

TEST(FaultSuiteTest, TruncatedPngIsSkipped) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "truncated");
  const fs::path image = Images(dataset).at(kFault);
  fs::resize_file(image, fs::file_size(image) / 2);
  ExpectFrameSkipped(RunPldvo(dataset, "run_truncated"), TestRoot() / "run_truncated", image,
                     "cannot decode image");
}

TEST(FaultSuiteTest, CorruptPngIsSkipped) {
  // A valid PNG signature and header chunk start, then garbage (the header CRC fails).
  const fs::path dataset = CopyOf(Sequence(kFrames), "corrupt");
  const fs::path image = Images(dataset).at(kFault);
  WriteText(image, std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16) + std::string(200, '\x5a'));
  ExpectFrameSkipped(RunPldvo(dataset, "run_corrupt"), TestRoot() / "run_corrupt", image,
                     "cannot decode image");
}

TEST(FaultSuiteTest, WrongSizeFrameIsSkipped) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "wrong_size");
  const fs::path image = Images(dataset).at(kFault);
  ASSERT_TRUE(cv::imwrite(image.string(), cv::Mat(120, 160, CV_8UC1, cv::Scalar(100))));
  ExpectFrameSkipped(RunPldvo(dataset, "run_wrong_size"), TestRoot() / "run_wrong_size", image,
                     "image is 160x120, the calibration expects 320x240");
}

// The choice among random starts runs the first frames before the run: a frame it cannot process
// there is skipped by every candidate (counted against each alike) and by the run.
TEST(FaultSuiteTest, RandomStartCandidatesSkipAWrongSizeFrame) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "wrong_size_random_start");
  const fs::path image = Images(dataset).at(kFault);
  ASSERT_TRUE(cv::imwrite(image.string(), cv::Mat(120, 160, CV_8UC1, cv::Scalar(100))));
  const fs::path out = TestRoot() / "run_wrong_size_random_start";
  const RunResult run =
      RunPldvo(dataset, "run_wrong_size_random_start", "--set odometry.random_start_candidates=2");
  ExpectFrameSkipped(run, out, image, "image is 160x120, the calibration expects 320x240");
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  ASSERT_TRUE(summary["random_start"].is_object()) << run.log;
  ASSERT_EQ(summary["random_start"]["candidates"].size(), 2u);
  for (const nlohmann::json& candidate : summary["random_start"]["candidates"]) {
    EXPECT_EQ(candidate["untracked"].get<int>(), 1) << candidate.dump();
  }
}

TEST(FaultSuiteTest, AllBlackFrameIsLostAndTrackingResumes) {
  ExpectReplacedFrameLost(cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)), "black");
}

TEST(FaultSuiteTest, AllWhiteFrameIsLostAndTrackingResumes) {
  ExpectReplacedFrameLost(cv::Mat(240, 320, CV_8UC1, cv::Scalar(255)), "white");
}

// A frame of uniform noise (a sensor glitch): it has texture everywhere, and the tracker's
// whitened inlier fraction can pass it; the intensity correlation does not (docs/tracking.md,
// "Lost detection against unrelated images"). kNoiseDraws draws.
TEST(FaultSuiteTest, NoiseFrameIsLostAndTrackingResumes) {
  cv::RNG rng(11);
  for (int draw = 0; draw < kNoiseDraws; ++draw) {
    SCOPED_TRACE("draw " + std::to_string(draw));
    cv::Mat noise(240, 320, CV_8UC1);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    ExpectReplacedFrameLost(noise, "noise_" + std::to_string(draw));
  }
}

// Timestamps: rgb.txt must list strictly increasing timestamps; a duplicate or a step back is
// rejected when the dataset is opened, naming rgb.txt and the line (decided: a frame order that
// is wrong in the list cannot be repaired by skipping one frame).
TEST(FaultSuiteTest, DuplicateTimestampIsRejectedWithFileAndLine) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "duplicate_stamp");
  // rgb.txt: two comment lines, then frame i on line i + 3. Frame 6 gets frame 5's timestamp.
  std::stringstream list(Slurp(dataset / "rgb.txt"));
  std::string text, line, previous_stamp;
  for (int n = 1; std::getline(list, line); ++n) {
    if (n == 9) line = previous_stamp + line.substr(line.find(' '));
    if (n >= 3) previous_stamp = line.substr(0, line.find(' '));
    text += line + "\n";
  }
  WriteText(dataset / "rgb.txt", text);
  ExpectFatalAtStart(RunPldvo(dataset, "run_duplicate_stamp"), TestRoot() / "run_duplicate_stamp",
                     (dataset / "rgb.txt").string() + ":9: timestamp");
}

TEST(FaultSuiteTest, DecreasingTimestampIsRejectedWithFileAndLine) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "decreasing_stamp");
  // Lines 8 and 9 (frames 5 and 6) swapped: line 9's timestamp goes back.
  std::stringstream list(Slurp(dataset / "rgb.txt"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(list, line);) lines.push_back(line);
  std::swap(lines[7], lines[8]);
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  WriteText(dataset / "rgb.txt", text);
  const RunResult run = RunPldvo(dataset, "run_decreasing_stamp");
  ExpectFatalAtStart(run, TestRoot() / "run_decreasing_stamp",
                     (dataset / "rgb.txt").string() + ":9: timestamp");
  EXPECT_NE(run.log.find("does not increase"), std::string::npos) << run.log;
}

TEST(FaultSuiteTest, NanInGroundTruthIsRejectedWithFileAndLine) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "nan_ground_truth");
  // groundtruth.txt: comment lines, then poses; the tx of the 5th pose becomes nan.
  std::stringstream poses(Slurp(dataset / "groundtruth.txt"));
  std::string text, line;
  int pose = 0, nan_line = 0;
  for (int n = 1; std::getline(poses, line); ++n) {
    if (!line.empty() && line[0] != '#' && ++pose == 5) {
      const size_t tx = line.find(' ') + 1;
      line = line.substr(0, tx) + "nan" + line.substr(line.find(' ', tx));
      nan_line = n;
    }
    text += line + "\n";
  }
  ASSERT_GT(nan_line, 0);
  WriteText(dataset / "groundtruth.txt", text);
  const RunResult run = RunPldvo(dataset, "run_nan_ground_truth");
  ExpectFatalAtStart(run, TestRoot() / "run_nan_ground_truth",
                     (dataset / "groundtruth.txt").string() + ":" + std::to_string(nan_line) +
                         ": 'nan' is not a finite number");
}

TEST(FaultSuiteTest, UnknownCameraModelIsRejectedWithFileLineAndKey) {
  const fs::path dataset = CopyOf(Sequence(kFrames), "camera_model");
  std::string yaml = Slurp(dataset / "camera.yaml");
  const size_t model = yaml.find("model: pinhole");
  ASSERT_NE(model, std::string::npos) << yaml;
  yaml.replace(model, 14, "model: fisheye");
  WriteText(dataset / "camera.yaml", yaml);
  const int line = 1 + static_cast<int>(std::count(yaml.begin(), yaml.begin() + model, '\n'));
  ExpectFatalAtStart(RunPldvo(dataset, "run_camera_model"), TestRoot() / "run_camera_model",
                     (dataset / "camera.yaml").string() + ":" + std::to_string(line) +
                         ": key 'model': unknown model 'fisheye'");
}

// A valid camera of the wrong size (--camera tum_fr1 is 640x480): every frame fails to load,
// naming its file; nothing is tracked, so the run exits 1 after writing its outputs.
TEST(FaultSuiteTest, CameraOfTheWrongSizeFailsEveryFrameAndExitsOne) {
  const RunResult run = RunPldvo(Sequence(kFrames), "run_wrong_camera", "--camera tum_fr1");
  const fs::path out = TestRoot() / "run_wrong_camera";
  EXPECT_EQ(run.exit_code, 1) << run.log;
  EXPECT_NE(run.log.find(Images(Sequence(kFrames)).front().string() +
                         ": image is 320x240, the calibration expects 640x480"),
            std::string::npos)
      << run.log;
  EXPECT_NE(run.log.find("no frame was tracked"), std::string::npos) << run.log;
  const std::vector<std::string> statuses = Statuses(out);
  EXPECT_EQ(statuses, std::vector<std::string>(kFrames, "failed"));
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  EXPECT_EQ(summary["failed_frames"], kFrames);
  EXPECT_EQ(summary["tracked"], 0);
}

TEST(FaultSuiteTest, OutputFolderThatCannotBeCreatedExitsOne) {
  // --out below a regular file: no folder can be made there (also for root).
  const fs::path blocker = TestRoot() / "not_a_folder";
  WriteText(blocker, "a file");
  const RunResult run = RunPldvo(Sequence(kFrames), "not_a_folder/out");
  EXPECT_EQ(run.exit_code, 1) << run.log;
  EXPECT_NE(run.log.find((blocker / "out").string()), std::string::npos) << run.log;
}

TEST(FaultSuiteTest, FailedTrajectoryWriteStopsTheRunAndExitsOne) {
  // trajectory.txt is a link to /dev/full: opening succeeds, every write fails with ENOSPC
  // (a full disk).
  const fs::path out = TestRoot() / "run_disk_full";
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out / "trajectory.txt");
  const RunResult run = RunPldvo(Sequence(kFrames), "run_disk_full");
  EXPECT_EQ(run.exit_code, 1) << run.log;
  EXPECT_NE(run.log.find("cannot write " + out.string() + "/trajectory.txt"), std::string::npos)
      << run.log;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
}

// The camera sees a blank wall (uniform gray) for 30 frames: every blank frame is processed and
// marked lost or reinitialized (the odometry restarts on a blank keyframe, which has no points),
// every frame has its timing.csv row, and once the scene is back the odometry re-initialises
// and tracks again.
TEST(FaultSuiteTest, BlankWallForThirtyFramesIsLostThenRecovers) {
  const int frames = kWallStart + kWallFrames + kWallAfter;
  const fs::path dataset = CopyOf(Sequence(frames), "wall");
  const std::vector<fs::path> images = Images(dataset);
  const cv::Mat wall(240, 320, CV_8UC1, cv::Scalar(128));
  for (int i = kWallStart; i < kWallStart + kWallFrames; ++i) {
    ASSERT_TRUE(cv::imwrite(images[i].string(), wall));
  }
  const RunResult run = RunPldvo(dataset, "run_wall");
  const fs::path out = TestRoot() / "run_wall";
  ASSERT_EQ(run.exit_code, 0) << run.log;
  const std::vector<std::string> statuses = Statuses(out);
  ASSERT_EQ(statuses.size(), static_cast<size_t>(frames));
  int tracked = 0;
  for (int i = 0; i < frames; ++i) {
    const bool blank = i >= kWallStart && i < kWallStart + kWallFrames;
    if (i < kWallStart) {
      EXPECT_TRUE(IsTrackedStatus(statuses[i])) << i << ": " << statuses[i];
    }
    if (blank) {
      EXPECT_TRUE(statuses[i] == "lost" || statuses[i] == "reinitialized")
          << i << ": " << statuses[i];
    }
    tracked += IsTrackedStatus(statuses[i]);
  }
  // After the wall: odometry.reinit_after_lost = 3 frames lost against the blank keyframe, the
  // third re-initialised (a fresh random map), then every frame tracked.
  const int wall_end = kWallStart + kWallFrames;
  EXPECT_EQ(statuses[wall_end + 2], "reinitialized");
  for (int i = wall_end + 3; i < frames; ++i) {
    EXPECT_TRUE(IsTrackedStatus(statuses[i])) << i << ": " << statuses[i];
  }
  const Trajectory trajectory = ReadTrajectoryTum((out / "trajectory.txt").string());
  EXPECT_EQ(trajectory.size(), static_cast<size_t>(tracked));
  const nlohmann::json summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  EXPECT_EQ(summary["frames"], frames);
  EXPECT_EQ(summary["failed_frames"], 0);
  EXPECT_GE(summary["lost_frames"].get<int>(), kWallFrames);
  EXPECT_GE(summary["reinitializations"].get<int>(), 1);
  EXPECT_GE(summary["lost_events"].get<int>(), 1);
}

}  // namespace
}  // namespace pldvo
