// `pldvo run --dataset DIR [--format F] [--camera FILE|tum_fr1|tum_fr2|tum_fr3] [--config FILE]
//            [--set key=value]... --out OUT`: the odometry on a dataset (docs/odometry.md).
// Config precedence: defaults < --config file < --format / --camera < --set.
// Writes, as the run goes:
//   OUT/config.yaml      the effective config (at start; `pldvo run --config OUT/config.yaml`
//                        repeats the run);
//   OUT/trajectory.txt   TUM format, world_from_cam, dataset timestamps, one line per tracked
//                        frame, flushed per line (a crash never loses what was written);
//   OUT/timing.csv       one row per frame: status, counts and the time of every component;
//   OUT/summary.json     at the end: counts, median / mean ms per component, and with ground
//                        truth rpe_cm_s, rpe_deg_s, ate_m, coverage (Sim(3)-aligned),
//                        scale_drift and window_scales (1 s windows);
//   OUT/trajectory_compare.txt  with odometry.compare_solver: the other solver's poses on the
//                        same tracking problems (summary.json `compare_solver`);
//   OUT/keyframe_maps.csv  with output.keyframe_map_error: each keyframe's map against the
//                        dataset's depth (summary.json `keyframe_maps`).
// A frame that fails to load is reported with its file, marked failed and skipped. Exit codes
// (docs/reliability.md): 0 done; 1 a fatal input or output fault (dataset files, camera, output
// folder, a failed write, no frame tracked at all); 2 a usage or config error.
#include <gflags/gflags.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "backend/bootstrap_refiner.h"
#include "backend/frame_preparer.h"
#include "backend/odometry.h"
#include "backend/odometry_config.h"
#include "backend/two_view_bootstrap.h"
#include "core/config_io.h"
#include "core/dataset.h"
#include "core/evaluation.h"
#include "core/trajectory_io.h"
#include "core/wall_clock.h"
#include "experiments/command.h"
#include "experiments/common_flags.h"
#include "experiments/run_outputs.h"
#include "experiments/solver_comparison.h"

DEFINE_int32(max_frames, 0, "Process only the first N frames (0 = all).");
DEFINE_bool(progress, true, "Show a progress bar when stderr is a terminal.");
DEFINE_bool(list_config, false, "Print every config key with its default and doc, then exit.");

namespace pldvo {
namespace {

// The per-frame timing columns, in timing.csv order; the summary's ms objects use the same keys.
struct TimingRow {
  double load = 0, pyramid = 0, detection = 0, description = 0, matching = 0, tracing = 0, wait = 0,
         reference = 0, tracking = 0, mapping = 0, tracking_thread = 0, total = 0;
};
const char* const kTimingKeys[] = {
    "load", "pyramid",   "detection", "description", "matching",        "tracing",
    "wait", "reference", "tracking",  "mapping",     "tracking_thread", "total"};
std::vector<double> Values(const TimingRow& row) {
  return {row.load, row.pyramid,   row.detection, row.description, row.matching,        row.tracing,
          row.wait, row.reference, row.tracking,  row.mapping,     row.tracking_thread, row.total};
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / values.size();
}

nlohmann::json NumberOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

class ProgressBar {
 public:
  ProgressBar(int total, bool enabled)
      : total_(total), enabled_(enabled), start_(WallClock::now()) {}
  void Update(int done, int lost) {
    if (!enabled_) return;
    const auto now = WallClock::now();
    if (done < total_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double seconds = std::chrono::duration<double>(now - start_).count();
    const int width = 30;
    const int filled = total_ > 0 ? width * done / total_ : width;
    std::fprintf(stderr, "\r[%s%s] %d/%d  %.1f fps  lost %d ", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), done, total_,
                 seconds > 0.0 ? done / seconds : 0.0, lost);
    if (done == total_) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  int total_;
  bool enabled_;
  WallClock::time_point start_;
  WallClock::time_point last_;
};

struct LoadedFrame {
  Frame frame;
  std::string error;  // non-empty when loading failed
  double load_ms = 0.0;
  // odometry.frontend_thread: the frame's per-image work, done on the loading thread.
  std::optional<PreparedFrame> prepared;
};

// Loads frame `index` and, with a `preparer`, prepares it on the same (loading) thread. A frame
// that is not a gray image of the camera's size is left unprepared: ProcessFrame reports it.
LoadedFrame LoadFrame(const Dataset& dataset, int index, FramePreparer* preparer) {
  LoadedFrame loaded;
  const auto start = WallClock::now();
  try {
    loaded.frame = dataset.Load(index);
    if (loaded.frame.image.empty()) loaded.error = "empty image " + loaded.frame.path;
  } catch (const std::exception& e) {
    loaded.error = e.what();
  }
  loaded.load_ms = MsSince(start);
  const cv::Mat& image = loaded.frame.image;
  const PinholeCamera& camera = dataset.camera();
  if (preparer != nullptr && loaded.error.empty() && image.channels() == 1 &&
      image.cols == camera.width && image.rows == camera.height) {
    try {
      loaded.prepared = preparer->Prepare(image);
    } catch (const std::exception&) {
      // Left unprepared: ProcessFrame(image) repeats the work and reports the failure.
    }
  }
  return loaded;
}

OdometryConfig LoadRunConfig(const CommandContext& context) {
  OdometryConfig config;
  if (!FLAGS_config.empty()) LoadConfigYaml(FLAGS_config, &config);
  if (!gflags::GetCommandLineFlagInfoOrDie("format").is_default) {
    config.dataset.format = FLAGS_format;
  }
  if (!FLAGS_camera.empty()) config.dataset.camera = FLAGS_camera;
  ApplyOverrides(context.config_overrides, &config);
  CheckOptionsOrThrow(config, "config");
  return config;
}

int RunOdometryCommand(const CommandContext& context) {
  if (FLAGS_list_config) {
    std::cout << DescribeConfig(OdometryConfig());
    return 0;
  }
  if (FLAGS_dataset.empty() || FLAGS_out.empty()) {
    std::cerr << "pldvo run: --dataset DIR and --out OUT are required (pldvo run --help)\n";
    return 2;
  }
  OdometryConfig config;
  try {
    config = LoadRunConfig(context);
  } catch (const std::exception& e) {
    std::cerr << "pldvo run: " << e.what() << "\n";
    return 2;
  }
  const std::string out = FLAGS_out;
  std::unique_ptr<Dataset> dataset;
  try {
    std::filesystem::create_directories(out);
    WriteConfigYaml(config, out + "/config.yaml");
    dataset = OpenDataset(FLAGS_dataset, config.dataset);
  } catch (const std::exception& e) {
    std::cerr << "pldvo run: " << e.what() << "\n";
    return 1;
  }

  std::ofstream trajectory_file(out + "/trajectory.txt");
  std::ofstream timing_file(out + "/timing.csv");
  if (!trajectory_file || !timing_file) {
    std::cerr << "pldvo run: cannot write into " << out << "\n";
    return 1;
  }
  // A failed write (disk full, folder removed) stops the run: its output could not be kept.
  const auto written = [&out](std::ostream& file, const char* name) {
    if (file.flush()) return true;
    std::cerr << "\npldvo run: cannot write " << out << "/" << name << ": " << std::strerror(errno)
              << "; stopping (lines written so far are kept)\n";
    return false;
  };
  trajectory_file << "# pldvo run: timestamp tx ty tz qx qy qz qw (world_from_cam), dataset "
                  << FLAGS_dataset << "\n";
  timing_file
      << "index,timestamp,status,keyframe_id,lines,matches,line_outliers,reference_points,"
         "alternatives,iterations,final_rms,inlier_fraction,intensity_correlation,brightness_a,"
         "brightness_b,pose_sigma_t,pose_sigma_r_deg";
  for (const char* key : kTimingKeys) timing_file << "," << key << "_ms";
  timing_file << "\n";
  if (!written(trajectory_file, "trajectory.txt") || !written(timing_file, "timing.csv")) return 1;

  const int num_frames =
      FLAGS_max_frames > 0 ? std::min(FLAGS_max_frames, dataset->size()) : dataset->size();
  RunOutputs outputs(out, config.output, dataset.get());
  // odometry.bootstrap_passes: the run starts from the refined first map instead of a random one
  // (or from the random one, said so, when the refinement fails).
  BootstrapRefinement bootstrap;
  OdometryConfig run_config = config;
  run_config.odometry.bootstrap_passes = 1;
  if (config.odometry.bootstrap_passes > 1 && num_frames > 0) {
    try {
      bootstrap = RefineBootstrap(*dataset, config, num_frames);
      run_config.odometry.init_depth_idepth_var = config.odometry.bootstrap_idepth_var;
      std::cerr << "pldvo run: bootstrap refinement: " << bootstrap.frames.size()
                << " passes before the run, first keyframe hypotheses " << bootstrap.points.back()
                << ", " << static_cast<int>(bootstrap.ms) << " ms\n";
    } catch (const std::exception& e) {
      bootstrap = BootstrapRefinement();
      std::cerr << "pldvo run: bootstrap refinement failed (" << e.what()
                << "); the run starts from the random map\n";
    }
  }
  // odometry.two_view_bootstrap: the run starts from frame 0's map of the two-view bootstrap
  // (or from the random map, said so, when it fails).
  TwoViewBootstrap two_view;
  run_config.odometry.two_view_bootstrap = false;  // the run starts from its map, as from depth
  if (config.odometry.two_view_bootstrap && num_frames > 0) {
    try {
      two_view = BootstrapFromTwoViews(*dataset, config, num_frames);
      bootstrap.depth = two_view.depth;
      run_config.odometry.init_depth_idepth_var = config.odometry.bootstrap_idepth_var;
      std::cerr << "pldvo run: two-view bootstrap: second view frame " << two_view.second_view
                << ", " << two_view.inliers << " of " << two_view.tracks
                << " corners triangulated, median parallax " << two_view.parallax_deg << " deg, "
                << two_view.points << " hypotheses, " << static_cast<int>(two_view.ms) << " ms\n";
    } catch (const std::exception& e) {
      two_view = TwoViewBootstrap();
      std::cerr << "pldvo run: " << e.what() << "; the run starts from the random map\n";
    }
  }
  std::unique_ptr<Odometry> odometry;
  try {
    odometry = std::make_unique<Odometry>(dataset->camera(), run_config, &outputs);
  } catch (const std::exception& e) {
    std::cerr << "pldvo run: " << e.what() << "\n";
    return 1;
  }

  std::unique_ptr<SolverComparison> comparison;
  if (config.odometry.compare_solver != OdometryOptions::CompareSolver::kNone) {
    comparison = std::make_unique<SolverComparison>(
        out + "/trajectory_compare.txt",
        config.odometry.compare_solver == OdometryOptions::CompareSolver::kCeres ? "ceres"
                                                                                 : "gauss_newton");
    if (!comparison->ok()) {
      std::cerr << "pldvo run: cannot write into " << out << "\n";
      return 1;
    }
  }

  ProgressBar progress(num_frames, FLAGS_progress && isatty(STDERR_FILENO));
  std::vector<TimingRow> rows;
  Trajectory estimate;
  int failed = 0;
  const auto run_start = WallClock::now();
  // Frame i + 1 is loaded (decoded, undistorted) while frame i is processed, and with
  // odometry.frontend_thread also prepared (pyramid, line detection and description). One task
  // runs at a time, so the preparer is never used by two threads at once.
  std::unique_ptr<FramePreparer> preparer;
  if (run_config.odometry.frontend_thread) preparer = std::make_unique<FramePreparer>(run_config);
  const auto load = [&](int index) {
    return std::async(std::launch::async, LoadFrame, std::cref(*dataset), index, preparer.get());
  };
  std::future<LoadedFrame> next;
  if (num_frames > 0) next = load(0);
  for (int i = 0; i < num_frames; ++i) {
    const auto frame_start = WallClock::now();
    LoadedFrame loaded = next.get();
    if (i + 1 < num_frames) next = load(i + 1);
    OdometryFrameResult result;
    if (!loaded.error.empty()) {
      std::cerr << (isatty(STDERR_FILENO) ? "\n" : "") << "pldvo run: frame " << i
                << " skipped: " << loaded.error << "\n";
      result = odometry->SkipFrame(i, dataset->timestamp(i), loaded.error);
    } else {
      try {
        cv::Mat depth;
        if (i == 0 && !bootstrap.depth.empty()) {
          depth = bootstrap.depth;
        } else if (i == 0 && config.odometry.init_depth_idepth_var > 0.0) {
          depth = dataset->LoadDepth(i);
          if (depth.empty()) {
            throw std::runtime_error(
                "odometry.init_depth_idepth_var: the dataset has no depth "
                "image for frame 0");
          }
        }
        result = loaded.prepared.has_value()
                     ? odometry->ProcessFrame(i, loaded.frame.timestamp,
                                              std::move(*loaded.prepared), depth)
                     : odometry->ProcessFrame(i, loaded.frame.timestamp, loaded.frame.image, depth);
      } catch (const std::exception& e) {
        std::cerr << "pldvo run: frame " << i << " (" << loaded.frame.path
                  << ") skipped: " << e.what() << "\n";
        result = odometry->SkipFrame(i, loaded.frame.timestamp, e.what());
      }
    }
    if (result.status == FrameStatus::kFailed) ++failed;
    if (IsTracked(result.status)) {
      const StampedPose pose{result.timestamp, result.world_from_cam};
      WriteTumLine(pose, trajectory_file);
      if (!written(trajectory_file, "trajectory.txt")) return 1;
      estimate.push_back(pose);
    }
    if (comparison != nullptr && !comparison->Add(result)) {
      std::cerr << "\npldvo run: cannot write " << out
                << "/trajectory_compare.txt: " << std::strerror(errno) << "; stopping\n";
      return 1;
    }
    TimingRow row;
    const OdometryTiming& t = result.timing;
    row.load = loaded.load_ms;
    row.pyramid = t.pyramid_ms;
    row.detection = t.detection_ms;
    row.description = t.description_ms;
    row.matching = t.matching_ms;
    row.tracing = t.tracing_ms;
    row.wait = t.wait_ms;
    row.reference = t.reference_ms;
    row.tracking = t.tracking_ms;
    row.mapping = t.mapping_ms;
    row.tracking_thread = t.tracking_thread_ms;
    row.total = MsSince(frame_start);
    if (result.status != FrameStatus::kFailed) rows.push_back(row);
    // RMS sigma per axis of the tracked pose (tracking.pose_covariance; 0 without it).
    const Matrix6d& pose_covariance = result.tracking.pose_covariance;
    const double pose_sigma_t = std::sqrt(pose_covariance.topLeftCorner<3, 3>().trace() / 3.0);
    const double pose_sigma_r_deg =
        std::sqrt(pose_covariance.bottomRightCorner<3, 3>().trace() / 3.0) * 180.0 / M_PI;
    timing_file << i << "," << std::setprecision(17) << result.timestamp << ","
                << FrameStatusName(result.status) << "," << result.keyframe_id << ","
                << result.num_lines << "," << result.num_matches << "," << result.num_line_outliers
                << "," << result.num_reference_points << "," << result.alternatives_tried << ","
                << result.tracking.TotalIterations() << "," << std::setprecision(6)
                << result.tracking.final_rms << "," << result.tracking.inlier_fraction << ","
                << result.tracking.intensity_correlation << "," << result.tracking.brightness.a
                << "," << result.tracking.brightness.b << "," << pose_sigma_t << ","
                << pose_sigma_r_deg;
    for (double value : Values(row)) timing_file << "," << std::setprecision(4) << value;
    timing_file << "\n";
    if (!written(timing_file, "timing.csv")) return 1;
    progress.Update(i + 1, odometry->statistics().lost_frames);
  }
  odometry->Finish();
  const double run_seconds = std::chrono::duration<double>(WallClock::now() - run_start).count();
  const OdometryStatistics stats = odometry->statistics();

  // Summary.
  nlohmann::json summary;
  summary["dataset"] = FLAGS_dataset;
  summary["config"] = FLAGS_config;
  summary["frames"] = num_frames;
  summary["tracked"] = stats.tracked;
  summary["keyframes"] = stats.keyframes;
  summary["lost_events"] = stats.lost_events;
  summary["lost_frames"] = stats.lost_frames;
  summary["failed_frames"] = failed;
  summary["reinitializations"] = stats.reinitializations;
  summary["dropped_mapping_updates"] = stats.dropped_mapping_updates;
  summary["failed_mapping_jobs"] = stats.failed_mapping_jobs;
  summary["parallel_mapping"] = config.odometry.parallel_mapping;
  summary["frontend_thread"] = config.odometry.frontend_thread;
  summary["seconds"] = run_seconds;
  // odometry.bootstrap_passes > 1: frames and first-keyframe hypotheses per refinement pass, and
  // their wall time (before the run; not in `seconds`).
  summary["bootstrap"] = nullptr;
  if (!bootstrap.frames.empty()) {
    summary["bootstrap"] = {
        {"frames", bootstrap.frames}, {"points", bootstrap.points}, {"ms", bootstrap.ms}};
  }
  // odometry.two_view_bootstrap: the second view, its triangulated corners and median parallax,
  // frame 0's hypotheses, wall time (before the run).
  summary["two_view_bootstrap"] = nullptr;
  if (two_view.second_view >= 0) {
    summary["two_view_bootstrap"] = {
        {"second_view", two_view.second_view}, {"tracks", two_view.tracks},
        {"inliers", two_view.inliers},         {"parallax_deg", two_view.parallax_deg},
        {"points", two_view.points},           {"ms", two_view.ms}};
  }
  summary["fps"] = run_seconds > 0.0 ? num_frames / run_seconds : 0.0;
  // Edge bundle adjustment (backend.edge_ba): windows solved, applied, CPU ms per window.
  summary["edge_ba_windows"] = stats.edge_ba_windows;
  summary["edge_ba_applied"] = stats.edge_ba_applied;
  summary["edge_ba_ms_median"] = Median(odometry->EdgeBAWindowTimesMs());
  // Line-depth feedback (backend.edge_ba.line_depth_feedback, docs/edge_ba.md).
  summary["edge_ba_covariance_ms_median"] = Median(odometry->EdgeBACovarianceTimesMs());
  summary["edge_ba_covariance_failures"] = stats.edge_ba_covariance_failures;
  summary["edge_ba_line_depth_jobs"] = stats.edge_ba_line_depth_jobs;
  summary["edge_ba_line_depths_fused"] = stats.edge_ba_line_depths_fused;
  summary["edge_ba_line_depth_outliers"] = stats.edge_ba_line_depth_outliers;
  nlohmann::json median = nlohmann::json::object(), mean = nlohmann::json::object();
  const std::vector<double> mapping_jobs = odometry->MappingJobTimesMs();
  for (size_t k = 0; k < std::size(kTimingKeys); ++k) {
    std::vector<double> column;
    for (const TimingRow& row : rows) column.push_back(Values(row)[k]);
    // Mapping: per mapping job (the per-frame column attributes parallel work to frames only
    // approximately).
    if (std::string(kTimingKeys[k]) == "mapping") column = mapping_jobs;
    median[kTimingKeys[k]] = Median(column);
    mean[kTimingKeys[k]] = Mean(column);
  }
  summary["ms_median"] = median;
  summary["ms_mean"] = mean;
  std::string evaluation_line;
  const Trajectory* ground_truth = dataset->ground_truth();
  if (ground_truth != nullptr && !ground_truth->empty()) {
    try {
      const EvaluationResult eval = EvaluateTrajectory(*ground_truth, estimate);
      summary["rpe_cm_s"] = NumberOrNull(eval.rpe_cm_s);
      summary["rpe_deg_s"] = NumberOrNull(eval.rpe_deg_s);
      summary["ate_m"] = eval.ate_m;
      summary["coverage"] = eval.coverage;
      summary["scale"] = eval.scale;
      summary["scale_drift"] = NumberOrNull(eval.scale_drift);
      summary["window_scales"] = eval.window_scales;
      std::ostringstream line;
      line << std::fixed << std::setprecision(3) << "RPE " << eval.rpe_cm_s << " cm/s, "
           << eval.rpe_deg_s << " deg/s; ATE " << std::setprecision(4) << eval.ate_m
           << " m; coverage " << std::setprecision(3) << eval.coverage;
      evaluation_line = line.str();
    } catch (const std::exception& e) {
      summary["rpe_cm_s"] = nullptr;
      summary["rpe_deg_s"] = nullptr;
      summary["ate_m"] = nullptr;
      summary["coverage"] = 0.0;
      summary["evaluation_error"] = e.what();
      evaluation_line = std::string("evaluation failed: ") + e.what();
    }
  }
  std::string map_line;
  if (config.output.keyframe_map_error) {
    summary["keyframe_maps"] = outputs.KeyframeMapSummary();
    const nlohmann::json& maps = summary["keyframe_maps"];
    std::ostringstream line;
    if (maps.is_null()) {
      line << "keyframe maps: none evaluated (no depth images?)";
    } else {
      line << std::setprecision(3) << "keyframe maps (" << maps["keyframes"].get<int>()
           << ", medians): rel. err " << maps["median_rel_error_median"].get<double>()
           << ", continuous: rel. err " << maps["continuous_median_rel_error_median"].get<double>()
           << ", mean NEES " << maps["continuous_mean_nees_median"].get<double>() << ", gross "
           << maps["continuous_gross_fraction_median"].get<double>();
    }
    map_line = line.str();
  }
  std::string comparison_line;
  if (comparison != nullptr) {
    summary["compare_solver"] = comparison->Summary(ground_truth);
    comparison_line = comparison->Line(summary["compare_solver"]);
  }
  {
    std::ofstream summary_file(out + "/summary.json");
    summary_file << summary.dump(2) << "\n";
    if (!summary_file) {
      std::cerr << "pldvo run: cannot write " << out << "/summary.json\n";
      return 1;
    }
  }

  std::cout << "pldvo run: " << num_frames << " frames, " << stats.tracked << " tracked, "
            << stats.keyframes << " keyframes, " << stats.lost_events << " lost events ("
            << stats.lost_frames << " frames), " << failed << " failed to load; " << std::fixed
            << std::setprecision(1) << summary["fps"].get<double>() << " frames/s\n";
  std::cout << "  component        median ms   mean ms\n";
  for (const char* key : kTimingKeys) {
    std::cout << "  " << std::left << std::setw(16) << key << std::right << std::setw(10)
              << std::setprecision(2) << median[key].get<double>() << std::setw(10)
              << mean[key].get<double>() << "\n";
  }
  if (!evaluation_line.empty()) std::cout << "  " << evaluation_line << "\n";
  if (!comparison_line.empty()) std::cout << "  " << comparison_line << "\n";
  if (!map_line.empty()) std::cout << "  " << map_line << "\n";
  std::cout << "  outputs in " << out << "\n";
  if (num_frames > 0 && stats.tracked == 0) {
    std::cerr << "pldvo run: no frame was tracked (" << failed
              << " failed to load); check the camera and the messages above\n";
    return 1;
  }
  return 0;
}

}  // namespace

PLDVO_REGISTER_COMMAND("run", "Monocular odometry with points and lines on a dataset.",
                       RunOdometryCommand, "dataset", "format", "camera", "config", "out");

}  // namespace pldvo
