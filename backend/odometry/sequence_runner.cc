#include "backend/odometry/sequence_runner.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
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
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "backend/odometry/backward_start.h"
#include "backend/odometry/bootstrap_refiner.h"
#include "backend/odometry/frame_preparer.h"
#include "backend/odometry/live_frame_source.h"
#include "backend/odometry/loaded_frame.h"
#include "backend/odometry/odometry.h"
#include "backend/odometry/random_start_choice.h"
#include "backend/odometry/solver_comparison.h"
#include "backend/odometry/two_view_bootstrap.h"
#include "core/config_io.h"
#include "core/evaluation.h"
#include "core/frame_range_view.h"
#include "core/statistics.h"
#include "core/trajectory_io.h"
#include "core/trajectory_svg.h"
#include "core/wall_clock.h"

namespace pldvo {
namespace {

// The per-frame timing columns, in timing.csv order; the summary's ms objects use the same keys.
const char* const kTimingKeys[] = {
    "load",      "pyramid",  "detection", "description", "matching",        "tracing", "wait",
    "reference", "tracking", "consensus", "mapping",     "tracking_thread", "total"};
constexpr size_t kNumTimingKeys = std::size(kTimingKeys);
using TimingRow = std::array<double, kNumTimingKeys>;

TimingRow MakeTimingRow(const OdometryTiming& t, double load_ms, double total_ms) {
  return {load_ms,       t.pyramid_ms,   t.detection_ms, t.description_ms,
          t.matching_ms, t.tracing_ms,   t.wait_ms,      t.reference_ms,
          t.tracking_ms, t.consensus_ms, t.mapping_ms,   t.tracking_thread_ms,
          total_ms};
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

// The line-by-line files of the run. Every write is flushed; a failed one (disk full, folder
// removed) throws RunOutputError: its output could not be kept.
class RunFiles {
 public:
  RunFiles(const std::string& out_dir, const std::string& dataset_label) : out_dir_(out_dir) {
    trajectory_.open(out_dir + "/trajectory.txt");
    timing_.open(out_dir + "/timing.csv");
    if (!trajectory_ || !timing_) throw RunOutputError("cannot write into " + out_dir);
    trajectory_ << "# pldvo run: timestamp tx ty tz qx qy qz qw (world_from_cam), dataset "
                << dataset_label << "\n";
    timing_ << "index,timestamp,status,keyframe_id,lines,matches,line_outliers,reference_points,"
               "alternatives,iterations,final_rms,inlier_fraction,intensity_correlation,"
               "brightness_a,brightness_b,pose_sigma_t,pose_sigma_r_deg,intensity_noise_sigma,"
               "line_noise_scale";
    for (const char* key : kTimingKeys) timing_ << "," << key << "_ms";
    timing_ << "\n";
    Flush(trajectory_, "trajectory.txt");
    Flush(timing_, "timing.csv");
  }

  void AddPose(const StampedPose& pose) {
    WriteTumLine(pose, trajectory_);
    Flush(trajectory_, "trajectory.txt");
  }

  void AddTimingRow(const OdometryFrameResult& result, const TimingRow& row) {
    // RMS sigma per axis of the tracked pose (tracking.pose_covariance; 0 without it).
    const Matrix6d& pose_covariance = result.tracking.pose_covariance;
    const double pose_sigma_t = std::sqrt(pose_covariance.topLeftCorner<3, 3>().trace() / 3.0);
    const double pose_sigma_r_deg =
        std::sqrt(pose_covariance.bottomRightCorner<3, 3>().trace() / 3.0) * 180.0 / M_PI;
    const TrackingResult& tracking = result.tracking;
    timing_ << result.index << "," << std::setprecision(17) << result.timestamp << ","
            << FrameStatusName(result.status) << "," << result.keyframe_id << ","
            << result.num_lines << "," << result.num_matches << "," << result.num_line_outliers
            << "," << result.num_reference_points << "," << result.alternatives_tried << ","
            << tracking.TotalIterations() << "," << std::setprecision(6) << tracking.final_rms
            << "," << tracking.inlier_fraction << "," << tracking.intensity_correlation << ","
            << tracking.brightness.a << "," << tracking.brightness.b << "," << pose_sigma_t << ","
            << pose_sigma_r_deg << "," << tracking.intensity_noise_sigma << ","
            << tracking.line_noise_scale;
    for (double value : row) timing_ << "," << std::setprecision(4) << value;
    timing_ << "\n";
    Flush(timing_, "timing.csv");
  }

 private:
  void Flush(std::ostream& file, const char* name) {
    if (file.flush()) return;
    throw RunOutputError("cannot write " + out_dir_ + "/" + name + ": " + std::strerror(errno) +
                         "; stopping (lines written so far are kept)");
  }

  std::string out_dir_;
  std::ofstream trajectory_;
  std::ofstream timing_;
};

// Where the run starts: the config it runs with and frame 0's depth, from the bootstraps.
struct InitialMap {
  OdometryConfig run_config;
  int first_frame = 0;          // the two-view start's anchor: the run proper starts there
  BackwardStart backward;       // first_frame > 0: the frames before it
  cv::Mat depth;                // first_frame's z-depth (empty: the dataset's or a random map)
  nlohmann::json bootstrap;     // summary.json `bootstrap` (null when not run)
  nlohmann::json two_view;      // summary.json `two_view_bootstrap` (null when not run)
  nlohmann::json random_start;  // summary.json `random_start` (null when not run)
};

// odometry.bootstrap_passes > 1 starts from the refined first map, odometry.init_depth_idepth_var
// > 0 from the dataset's depth, otherwise odometry.two_view_bootstrap from the map of the two-view
// geometry; a bootstrap that fails falls back to the random map, said so, whose initial values
// odometry.random_start_candidates > 1 chooses among several.
InitialMap PrepareInitialMap(const Dataset& dataset, const OdometryConfig& config, int num_frames,
                             bool realtime) {
  InitialMap initial;
  initial.run_config = config;
  initial.run_config.odometry.bootstrap_passes = 1;
  initial.run_config.odometry.two_view_bootstrap = false;  // the run starts from its map
  if (config.odometry.bootstrap_passes > 1 && num_frames > 0) {
    try {
      const BootstrapRefinement refined = RefineBootstrap(dataset, config, num_frames);
      initial.depth = refined.depth;
      initial.run_config.odometry.init_depth_idepth_var = config.odometry.bootstrap_idepth_var;
      initial.bootstrap = {
          {"frames", refined.frames}, {"points", refined.points}, {"ms", refined.ms}};
      std::cerr << "pldvo run: bootstrap refinement: " << refined.frames.size()
                << " passes before the run, first keyframe hypotheses " << refined.points.back()
                << ", " << static_cast<int>(refined.ms) << " ms\n";
    } catch (const std::exception& e) {
      std::cerr << "pldvo run: bootstrap refinement failed (" << e.what()
                << "); the run starts from the random map\n";
    }
  }
  // Where the two-view start fails only at its direction gate: its corners, for the random start.
  CornerTracks unsettled_corners;
  if (config.odometry.two_view_bootstrap && config.odometry.bootstrap_passes <= 1 &&
      config.odometry.init_depth_idepth_var <= 0.0 && num_frames > 0) {
    // From frame 0, and where its corners are lost before a second view, again from the frame
    // where they were lost, or where the direction gate failed, from the first frame that passed
    // the parallax gates (TwoViewRestartFrame; up to two_view_max_anchor; not live, where the
    // frames before it have gone by).
    const int max_anchor = realtime ? 0 : config.odometry.two_view_max_anchor;
    int anchor = 0;
    while (true) {
      try {
        const FrameRangeView from_anchor(dataset, anchor, FrameRangeView::Direction::kForward);
        const TwoViewBootstrap two_view =
            anchor == 0 ? BootstrapFromTwoViews(dataset, config, num_frames, &unsettled_corners)
                        : BootstrapFromTwoViews(from_anchor, config, num_frames - anchor);
        // The run's config from that map; the frames before a later anchor, backwards from it.
        OdometryConfig run_config = initial.run_config;
        run_config.odometry.init_depth_idepth_var = config.odometry.bootstrap_idepth_var;
        BackwardStart backward;
        if (anchor > 0) {
          backward = TrackBackwardFromAnchor(dataset, run_config, anchor, two_view.depth);
        }
        initial.run_config = run_config;
        initial.first_frame = anchor;
        initial.depth = two_view.depth;
        initial.backward = std::move(backward);
        initial.two_view = {{"anchor", anchor},
                            {"second_view", anchor + two_view.second_view},
                            {"tracks", two_view.tracks},
                            {"inliers", two_view.inliers},
                            {"parallax_deg", two_view.parallax_deg},
                            {"rotation_free_parallax_px", two_view.rotation_free_parallax_px},
                            {"direction_std_deg", two_view.direction_std_deg},
                            {"photometric_points", two_view.photometric_points},
                            {"points", two_view.points},
                            {"ms", two_view.ms}};
        std::cerr << "pldvo run: two-view bootstrap: second view frame "
                  << anchor + two_view.second_view << ", " << two_view.inliers << " of "
                  << two_view.tracks << " corners triangulated, median parallax "
                  << two_view.parallax_deg << " deg, rotation-free "
                  << two_view.rotation_free_parallax_px << " px, direction std "
                  << two_view.direction_std_deg << " deg, " << two_view.photometric_points
                  << " points refined photometrically, " << two_view.points << " hypotheses, "
                  << static_cast<int>(two_view.ms) << " ms\n";
        if (anchor > 0) {
          const OdometryStatistics& back = initial.backward.statistics;
          initial.two_view["backward"] = {{"frames", anchor},
                                          {"tracked", initial.backward.poses.size()},
                                          {"keyframes", back.keyframes},
                                          {"lost_events", back.lost_events},
                                          {"scale_segments", back.scale_segments},
                                          {"ms", initial.backward.ms}};
          std::cerr << "pldvo run: frames 0-" << anchor - 1 << " tracked backwards from frame "
                    << anchor << "'s map: " << initial.backward.poses.size() << " tracked, "
                    << back.lost_events << " lost events, " << static_cast<int>(initial.backward.ms)
                    << " ms\n";
        }
        break;
      } catch (const std::exception& e) {
        // A later start's frames are numbered from its anchor in the message.
        const std::string where =
            anchor > 0 ? "the start from frame " + std::to_string(anchor) + ": " : "";
        const auto* failure = dynamic_cast<const TwoViewBootstrapFailure*>(&e);
        const int restart =
            failure != nullptr
                ? TwoViewRestartFrame(*failure,
                                      config.odometry.two_view_reanchor_after_direction_gate)
                : -1;
        const int next = anchor + restart;
        if (restart < 0 || next > max_anchor || num_frames - next < 2) {
          std::cerr << "pldvo run: " << where << e.what()
                    << "; the run starts from the random map\n";
          break;
        }
        std::cerr << "pldvo run: " << where << e.what() << "; starting again from frame " << next
                  << "\n";
        anchor = next;
      }
    }
  }
  if (initial.depth.empty() && initial.run_config.odometry.init_depth_idepth_var <= 0.0 &&
      config.odometry.random_start_candidates > 1 && num_frames > 1) {
    try {
      const RandomStartChoice choice =
          ChooseRandomStart(dataset, initial.run_config, num_frames,
                            unsettled_corners.positions.empty() ? nullptr : &unsettled_corners);
      initial.run_config.mapping.init_seed = choice.init_seed;
      nlohmann::json candidates = nlohmann::json::array();
      for (const RandomStartCandidate& c : choice.candidates) {
        candidates.push_back({{"init_seed", c.init_seed},
                              {"untracked", c.untracked},
                              {"mean_correlation", c.mean_correlation},
                              {"mean_rms", c.mean_rms},
                              {"corner_error_px", NumberOrNull(c.corner_error_px)}});
      }
      initial.random_start = {{"init_seed", choice.init_seed},
                              {"score", choice.by_corners ? "corners" : "correlation"},
                              {"frames", choice.frames},
                              {"candidates", candidates},
                              {"ms", choice.ms}};
      std::cerr << "pldvo run: random start: mapping.init_seed " << choice.init_seed << " of "
                << choice.candidates.size() << " initial maps fits frames 1-" << choice.frames - 1
                << (choice.by_corners ? " and the tracked corners" : "") << " best, "
                << static_cast<int>(choice.ms) << " ms\n";
    } catch (const std::exception& e) {
      std::cerr << "pldvo run: random start choice failed (" << e.what()
                << "); the run starts from mapping.init_seed " << config.mapping.init_seed << "\n";
    }
  }
  return initial;
}

// The offline feed: every frame from `first` on in order, frame i + 1 loaded (and prepared) on
// another thread while frame i is processed. One task runs at a time, so the preparer is never
// used by two threads at once.
class PrefetchingFrameSource {
 public:
  PrefetchingFrameSource(const Dataset& dataset, int num_frames, FramePreparer* preparer, int first)
      : dataset_(dataset), num_frames_(num_frames), preparer_(preparer), index_(first) {
    if (index_ < num_frames_) next_ = Load(index_);
  }
  std::optional<std::pair<int, LoadedFrame>> Next() {
    if (index_ >= num_frames_) return std::nullopt;
    LoadedFrame frame = next_.get();
    const int index = index_++;
    if (index_ < num_frames_) next_ = Load(index_);
    return std::make_pair(index, std::move(frame));
  }

 private:
  std::future<LoadedFrame> Load(int index) {
    return std::async(std::launch::async, LoadFrame, std::cref(dataset_), index, preparer_);
  }
  const Dataset& dataset_;
  const int num_frames_;
  FramePreparer* preparer_;
  int index_;
  std::future<LoadedFrame> next_;
};

// The process's resident memory now and at its peak, MB.
double CurrentRssMb() {
  std::ifstream statm("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  if (!(statm >> pages_total >> pages_resident)) return 0.0;
  return pages_resident * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}
double PeakRssMb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return usage.ru_maxrss / 1024.0;  // KiB on Linux
}
constexpr int kRssSampleFrames = 100;

// One frame through the odometry; a frame that fails to load or process is skipped, said so.
OdometryFrameResult ProcessLoadedFrame(const Dataset& dataset, const InitialMap& initial,
                                       const OdometryConfig& config, int i, LoadedFrame loaded,
                                       Odometry* odometry) {
  if (!loaded.error.empty()) {
    std::cerr << (isatty(STDERR_FILENO) ? "\n" : "") << "pldvo run: frame " << i
              << " skipped: " << loaded.error << "\n";
    return odometry->SkipFrame(i, dataset.timestamp(i), loaded.error);
  }
  try {
    cv::Mat depth;
    if (i == initial.first_frame && !initial.depth.empty()) {
      depth = initial.depth;
    } else if (i == 0 && config.odometry.init_depth_idepth_var > 0.0) {
      depth = dataset.LoadDepth(i);
      if (depth.empty()) {
        throw std::runtime_error(
            "odometry.init_depth_idepth_var: the dataset has no depth image for frame 0");
      }
    }
    return loaded.prepared.has_value()
               ? odometry->ProcessFrame(i, loaded.frame.timestamp, std::move(*loaded.prepared),
                                        depth)
               : odometry->ProcessFrame(i, loaded.frame.timestamp, loaded.frame.image, depth);
  } catch (const std::exception& e) {
    std::cerr << "pldvo run: frame " << i << " (" << loaded.frame.path << ") skipped: " << e.what()
              << "\n";
    return odometry->SkipFrame(i, loaded.frame.timestamp, e.what());
  }
}

// summary.json's ms_median and ms_mean: per component over the frames that were not failed;
// mapping per mapping job (the per-frame column attributes parallel work to frames only
// approximately).
void AddTimingSummary(const std::vector<TimingRow>& rows, const std::vector<double>& mapping_jobs,
                      nlohmann::json* summary) {
  nlohmann::json median = nlohmann::json::object(), mean = nlohmann::json::object();
  for (size_t k = 0; k < kNumTimingKeys; ++k) {
    std::vector<double> column;
    for (const TimingRow& row : rows) column.push_back(row[k]);
    if (std::string(kTimingKeys[k]) == "mapping") column = mapping_jobs;
    median[kTimingKeys[k]] = Median(column);
    mean[kTimingKeys[k]] = Mean(column);
  }
  (*summary)["ms_median"] = median;
  (*summary)["ms_mean"] = mean;
}

// The accuracy against the dataset's ground truth into the summary; the report's line.
std::string AddEvaluation(const Trajectory& ground_truth, const Trajectory& estimate,
                          const EvaluationOptions& options, nlohmann::json* summary,
                          Sim3Alignment* gt_from_est) {
  nlohmann::json& s = *summary;
  try {
    const EvaluationResult eval = EvaluateTrajectory(ground_truth, estimate, options);
    *gt_from_est = eval.gt_from_est;
    s["rpe_cm_s"] = NumberOrNull(eval.rpe_cm_s);
    s["rpe_deg_s"] = NumberOrNull(eval.rpe_deg_s);
    s["rpe_cm_s_still"] = NumberOrNull(eval.rpe_cm_s_still);
    s["ate_m"] = eval.ate_m;
    s["coverage"] = eval.coverage;
    s["scale"] = eval.scale;
    s["scale_drift"] = NumberOrNull(eval.scale_drift);
    s["window_scales"] = eval.window_scales;
    s["ground_truth_constant_velocity_start"] = eval.constant_velocity_start_poses;
    s["skipped_ground_truth_poses"] = eval.skipped_ground_truth_poses;
    std::ostringstream line;
    line << std::fixed << std::setprecision(3) << "RPE " << eval.rpe_cm_s << " cm/s (still "
         << eval.rpe_cm_s_still << "), " << eval.rpe_deg_s << " deg/s; ATE " << std::setprecision(4)
         << eval.ate_m << " m; coverage " << std::setprecision(3) << eval.coverage;
    if (eval.skipped_ground_truth_poses > 0) {
      line << "; from ground-truth pose " << eval.skipped_ground_truth_poses
           << " on (the poses before move at one constant velocity)";
    } else if (eval.constant_velocity_start_poses > 0) {
      line << "; the ground truth's first " << eval.constant_velocity_start_poses
           << " poses move at one constant velocity (extrapolated?"
           << " evaluation.skip_constant_velocity_start)";
    }
    return line.str();
  } catch (const std::exception& e) {
    s["rpe_cm_s"] = nullptr;
    s["rpe_deg_s"] = nullptr;
    s["rpe_cm_s_still"] = nullptr;
    s["ate_m"] = nullptr;
    s["coverage"] = 0.0;
    s["evaluation_error"] = e.what();
    return std::string("evaluation failed: ") + e.what();
  }
}

// motion_errors.csv and summary.json's medians of its columns (docs/evaluation.md).
void AddFrameMotionErrors(const Trajectory& ground_truth, const Trajectory& estimate, double scale,
                          double max_time_diff, const std::string& out, nlohmann::json* summary) {
  const std::vector<FrameMotionError> errors =
      EvaluateFrameMotion(ground_truth, estimate, scale, max_time_diff);
  std::ofstream file(out + "/motion_errors.csv");
  WriteFrameMotionErrorsCsv(errors, file);
  if (!file) throw RunOutputError("cannot write " + out + "/motion_errors.csv");
  std::vector<double> rotation, direction;
  for (const FrameMotionError& error : errors) {
    rotation.push_back(error.rotation_error_deg);
    if (!std::isnan(error.translation_direction_error_deg)) {
      direction.push_back(error.translation_direction_error_deg);
    }
  }
  const auto median_or_nan = [](const std::vector<double>& values) {
    return values.empty() ? std::numeric_limits<double>::quiet_NaN() : Median(values);
  };
  (*summary)["motion_rotation_error_deg_median"] = NumberOrNull(median_or_nan(rotation));
  (*summary)["motion_direction_error_deg_median"] = NumberOrNull(median_or_nan(direction));
  (*summary)["motion_rotation_ratio"] = NumberOrNull(PooledRotationRatio(errors));
}

// OUT/trajectory.svg: the estimate, Sim(3)-aligned when there is ground truth, over it.
void WriteRunSvg(const std::string& path, const std::string& title, const Trajectory* ground_truth,
                 const Trajectory& estimate, const Sim3Alignment* gt_from_est) {
  std::vector<Eigen::Vector3d> gt_positions;
  if (ground_truth != nullptr) {
    for (const StampedPose& pose : *ground_truth) {
      gt_positions.push_back(pose.world_from_cam.translation());
    }
  }
  SvgCurve curve;
  curve.label = gt_from_est != nullptr ? "estimate (Sim(3)-aligned)" : "estimate";
  for (const StampedPose& pose : estimate) {
    const Eigen::Vector3d p = pose.world_from_cam.translation();
    curve.positions.push_back(gt_from_est != nullptr ? (*gt_from_est) * p : p);
  }
  WriteTrajectorySvg(path, title, gt_positions, {curve});
}

}  // namespace

SequenceRunner::SequenceRunner(const Dataset& dataset, const OdometryConfig& config,
                               SequenceRunOptions options, RunObserver* observer)
    : dataset_(dataset), config_(config), options_(std::move(options)), observer_(observer) {}

SequenceRunResult SequenceRunner::Run() {
  const std::string& out = options_.out_dir;
  try {
    std::filesystem::create_directories(out);
    WriteConfigYaml(config_, out + "/config.yaml");
  } catch (const std::exception& e) {
    throw RunOutputError(e.what());
  }
  RunFiles files(out, options_.dataset_label);
  const Trajectory* ground_truth = dataset_.ground_truth();
  if (ground_truth != nullptr && !ground_truth->empty()) {
    try {
      WriteTrajectoryTum(*ground_truth, out + "/groundtruth.txt");
    } catch (const std::exception& e) {
      throw RunOutputError(e.what());
    }
  }

  const int num_frames =
      options_.max_frames > 0 ? std::min(options_.max_frames, dataset_.size()) : dataset_.size();
  const InitialMap initial = PrepareInitialMap(dataset_, config_, num_frames, options_.realtime);
  Odometry odometry(dataset_.camera(), initial.run_config, observer_);

  std::unique_ptr<SolverComparison> comparison;
  if (config_.odometry.compare_solver != OdometryOptions::CompareSolver::kNone) {
    comparison = std::make_unique<SolverComparison>(
        out + "/trajectory_compare.txt",
        config_.odometry.compare_solver == OdometryOptions::CompareSolver::kCeres ? "ceres"
                                                                                  : "gauss_newton");
    if (!comparison->ok()) throw RunOutputError("cannot write into " + out);
  }

  ProgressBar progress(num_frames, options_.progress && isatty(STDERR_FILENO));
  std::vector<TimingRow> rows;
  Trajectory estimate;
  // Per entry of `estimate`: its keyframe id and kf_from_cam.
  std::vector<std::pair<int, SE3>> anchors;
  int failed = 0;
  std::vector<double> rss_mb;  // every kRssSampleFrames frames
  std::unique_ptr<FramePreparer> preparer;
  if (initial.run_config.odometry.frontend_thread) {
    preparer = std::make_unique<FramePreparer>(initial.run_config);
  }
  PrefetchingFrameSource offline(dataset_, options_.realtime ? 0 : num_frames, preparer.get(),
                                 initial.first_frame);
  // A re-anchored two-view start: the frames before it, tracked backwards (no keyframe of the run
  // proper: trajectory_ba.txt leaves them out).
  for (const StampedPose& pose : initial.backward.poses) {
    files.AddPose(pose);
    estimate.push_back(pose);
    anchors.push_back({-1, SE3()});
    if (comparison != nullptr && !comparison->AddUncompared(pose)) {
      throw RunOutputError("cannot write " + out +
                           "/trajectory_compare.txt: " + std::strerror(errno) + "; stopping");
    }
  }
  LiveFrameSource<LoadedFrame> live(dataset_, options_.realtime ? num_frames : 0, [&](int index) {
    return LoadFrame(dataset_, index, preparer.get());
  });
  const auto run_start = WallClock::now();
  if (options_.realtime) live.Start();
  int processed = 0;
  while (true) {
    // Offline, `total` includes waiting for the frame's loading; live, waiting for the camera
    // is not work.
    auto frame_start = WallClock::now();
    std::optional<std::pair<int, LoadedFrame>> next =
        options_.realtime ? live.Next() : offline.Next();
    if (!next.has_value()) break;
    if (options_.realtime) frame_start = WallClock::now();
    const int i = next->first;
    const double load_ms = next->second.load_ms;
    const OdometryFrameResult result =
        ProcessLoadedFrame(dataset_, initial, config_, i, std::move(next->second), &odometry);
    ++processed;
    if (result.status == FrameStatus::kFailed) ++failed;
    if (IsTracked(result.status)) {
      const StampedPose pose{result.timestamp, result.world_from_cam};
      files.AddPose(pose);
      estimate.push_back(pose);
      // The frame relative to the keyframe it belongs to (identity for a keyframe), for the
      // trajectory re-anchored to the keyframes' final BA poses.
      anchors.push_back({result.keyframe_id, result.status == FrameStatus::kKeyframe
                                                 ? SE3()
                                                 : result.tracking.cur_from_ref.Inverse()});
    }
    if (comparison != nullptr && !comparison->Add(result)) {
      throw RunOutputError("cannot write " + out +
                           "/trajectory_compare.txt: " + std::strerror(errno) + "; stopping");
    }
    const TimingRow row = MakeTimingRow(result.timing, load_ms, MsSince(frame_start));
    if (result.status != FrameStatus::kFailed) rows.push_back(row);
    files.AddTimingRow(result, row);
    if (processed % kRssSampleFrames == 0) rss_mb.push_back(CurrentRssMb());
    progress.Update(i + 1, odometry.statistics().lost_frames);
  }
  odometry.Finish();
  const double run_seconds = std::chrono::duration<double>(WallClock::now() - run_start).count();
  const OdometryStatistics stats = odometry.statistics();

  // The frames before a re-anchored start count as tracked or lost where the backward pass left
  // them (its anchor frame is the run's first), its re-initialisations as scale segments.
  const OdometryStatistics& back = initial.backward.statistics;
  const int tracked = stats.tracked + static_cast<int>(initial.backward.poses.size());
  const int lost_events = stats.lost_events + back.lost_events;
  const int lost_frames = stats.lost_frames + back.lost_frames;
  const int scale_segments = stats.scale_segments + std::max(0, back.scale_segments - 1);

  SequenceRunResult result;
  result.frames = num_frames;
  result.tracked = tracked;
  result.failed = failed;
  nlohmann::json& summary = result.summary;
  summary["dataset"] = options_.dataset_label;
  summary["config"] = options_.config_label;
  summary["frames"] = num_frames;
  summary["tracked"] = tracked;
  summary["keyframes"] = stats.keyframes;
  summary["lost_events"] = lost_events;
  summary["lost_frames"] = lost_frames;
  summary["failed_frames"] = failed;
  summary["reinitializations"] = stats.reinitializations;
  // Pieces of the trajectory with one scale: a re-initialisation with a fresh random map starts
  // a new one (OdometryStatistics::scale_segments).
  summary["scale_segments"] = scale_segments;
  summary["line_term_drops"] = stats.line_term_drops;
  summary["line_term_withheld"] = stats.line_term_withheld;
  summary["alternatives_gated"] = stats.alternatives_gated;
  summary["dropped_mapping_updates"] = stats.dropped_mapping_updates;
  summary["failed_mapping_jobs"] = stats.failed_mapping_jobs;
  // The stereo of every mapping update, summed over the run (FrameUpdateStats; the keys in
  // docs/odometry.md): searches, line-guided matches, fusions, outliers, removed and filled.
  const FrameUpdateStats stereo = odometry.StereoCounts();
  summary["stereo"] = {{"ssd_attempts", stereo.ssd_attempts},
                       {"ssd_ok", stereo.ssd_ok},
                       {"ssd_interval_end", stereo.ssd_interval_end},
                       {"ssd_skipped", stereo.ssd_skipped},
                       {"line_attempts", stereo.line_attempts},
                       {"line_ok", stereo.line_ok},
                       {"line_refined", stereo.line_refined},
                       {"line_fallback", stereo.line_fallback},
                       {"line_rejected", stereo.line_rejected},
                       {"line_narrow_prior", stereo.line_narrow_prior},
                       {"fused", stereo.fused},
                       {"created", stereo.created},
                       {"not_created", stereo.not_created},
                       {"outliers", stereo.outliers},
                       {"removed", stereo.removed},
                       {"filled", stereo.filled}};
  summary["parallel_mapping"] = config_.odometry.parallel_mapping;
  summary["frontend_thread"] = config_.odometry.frontend_thread;
  summary["seconds"] = run_seconds;
  // Frames the loop took, from initial.first_frame on; --realtime: frames dropped because the
  // odometry could not take them in time.
  summary["realtime"] = options_.realtime;
  summary["processed_frames"] = processed;
  summary["dropped_frames"] = options_.realtime ? live.dropped().size() : 0;
  summary["peak_rss_mb"] = PeakRssMb();
  summary["rss_mb_every_100_frames"] = rss_mb;
  // Before the run, not in `seconds`: frames and first-keyframe hypotheses per refinement pass;
  // the two-view bootstrap's second view, triangulated corners, parallax and hypotheses.
  summary["bootstrap"] = initial.bootstrap;
  summary["two_view_bootstrap"] = initial.two_view;
  // odometry.random_start_candidates: the initial maps tried and the one the run started from.
  summary["random_start"] = initial.random_start;
  // The run proper's frames (from a re-anchored start's anchor on) per second.
  summary["fps"] = run_seconds > 0.0 ? (num_frames - initial.first_frame) / run_seconds : 0.0;
  // Edge bundle adjustment (backend.edge_ba): windows solved, applied, CPU ms per window, and
  // the line-depth feedback (backend.edge_ba.line_depth_feedback, docs/edge_ba.md).
  summary["edge_ba_windows"] = stats.edge_ba_windows;
  summary["edge_ba_applied"] = stats.edge_ba_applied;
  summary["edge_ba_ms_median"] = Median(odometry.EdgeBAWindowTimesMs());
  summary["edge_ba_covariance_ms_median"] = Median(odometry.EdgeBACovarianceTimesMs());
  summary["edge_ba_covariance_failures"] = stats.edge_ba_covariance_failures;
  summary["edge_ba_line_depth_jobs"] = stats.edge_ba_line_depth_jobs;
  summary["edge_ba_line_depths_fused"] = stats.edge_ba_line_depths_fused;
  summary["edge_ba_line_depth_outliers"] = stats.edge_ba_line_depth_outliers;
  if (config_.backend.windowed_ba.enabled) {
    // Windowed BA (backend.windowed_ba, docs/windowed_ba.md): windows solved and applied, ms per
    // window on the solving thread, points and iterations per window; OUT/keyframes_ba.txt and
    // OUT/trajectory_ba.txt (the frames re-anchored to their keyframes' final poses).
    nlohmann::json ba;
    ba["windows"] = stats.windowed_ba_windows;
    ba["applied"] = stats.windowed_ba_applied;
    ba["failures"] = stats.windowed_ba_failures;
    ba["ms_median"] = Median(odometry.WindowedBATimesMs());
    ba["ms_mean"] = Mean(odometry.WindowedBATimesMs());
    ba["points_median"] = Median(odometry.WindowedBAPoints());
    ba["iterations_median"] = Median(odometry.WindowedBAIterations());
    ba["outlier_targets_median"] = Median(odometry.WindowedBAOutlierTargets());
    ba["idepth_jobs"] = stats.windowed_ba_idepth_jobs;
    ba["idepths_corrected"] = stats.windowed_ba_idepths_corrected;
    ba["prior_windows"] = stats.windowed_ba_prior_windows;
    Trajectory keyframes_ba;
    std::map<int, SE3> final_world_from_kf;
    for (const KeyframePoseRecord& record : odometry.WindowedBAKeyframePoses()) {
      keyframes_ba.push_back({record.timestamp, record.world_from_kf});
      final_world_from_kf[record.id] = record.world_from_kf;
    }
    // Every tracked frame re-anchored to its keyframe's final pose: world_from_kf_final *
    // kf_from_cam (what the trajectory would be had the later windows been known when it was
    // output).
    Trajectory reanchored;
    for (size_t i = 0; i < estimate.size(); ++i) {
      const auto it = final_world_from_kf.find(anchors[i].first);
      if (it != final_world_from_kf.end()) {
        reanchored.push_back({estimate[i].timestamp, it->second * anchors[i].second});
      }
    }
    try {
      WriteTrajectoryTum(keyframes_ba, out + "/keyframes_ba.txt");
      WriteTrajectoryTum(reanchored, out + "/trajectory_ba.txt");
    } catch (const std::exception& e) {
      throw RunOutputError(e.what());
    }
    if (ground_truth != nullptr && !ground_truth->empty()) {
      // The keyframe poses as the trajectory gave them (tracked, re-anchored at the time) and
      // after the BA: ATE over the keyframes (Sim(3)-aligned); the re-anchored frames: RPE and
      // ATE. Each evaluation on its own (a short run may have too few keyframes).
      Trajectory keyframes_tracked;
      for (const StampedPose& pose : estimate) {
        for (const StampedPose& keyframe : keyframes_ba) {
          if (keyframe.timestamp == pose.timestamp) keyframes_tracked.push_back(pose);
        }
      }
      try {
        ba["keyframes_ate_m_tracked"] =
            EvaluateTrajectory(*ground_truth, keyframes_tracked, config_.evaluation).ate_m;
        ba["keyframes_ate_m_ba"] =
            EvaluateTrajectory(*ground_truth, keyframes_ba, config_.evaluation).ate_m;
      } catch (const std::exception& e) {
        ba["keyframes_evaluation_error"] = e.what();
      }
      try {
        const EvaluationResult eval =
            EvaluateTrajectory(*ground_truth, reanchored, config_.evaluation);
        ba["reanchored_rpe_cm_s"] = NumberOrNull(eval.rpe_cm_s);
        ba["reanchored_rpe_deg_s"] = NumberOrNull(eval.rpe_deg_s);
        ba["reanchored_ate_m"] = eval.ate_m;
      } catch (const std::exception& e) {
        ba["reanchored_evaluation_error"] = e.what();
      }
    }
    summary["windowed_ba"] = ba;
  }
  AddTimingSummary(rows, odometry.MappingJobTimesMs(), &summary);

  std::ostringstream header;
  header << num_frames << " frames, " << tracked << " tracked, " << stats.keyframes
         << " keyframes, " << lost_events << " lost events (" << lost_frames << " frames), "
         << failed << " failed to load; " << std::fixed << std::setprecision(1)
         << summary["fps"].get<double>() << " frames/s";
  result.report.push_back(header.str());
  result.report.push_back("  component        median ms   mean ms");
  for (const char* key : kTimingKeys) {
    std::ostringstream line;
    line << "  " << std::left << std::setw(16) << key << std::right << std::fixed
         << std::setprecision(2) << std::setw(10) << summary["ms_median"][key].get<double>()
         << std::setw(10) << summary["ms_mean"][key].get<double>();
    result.report.push_back(line.str());
  }

  Sim3Alignment gt_from_est;
  bool aligned = false;
  if (ground_truth != nullptr && !ground_truth->empty()) {
    const std::string line =
        AddEvaluation(*ground_truth, estimate, config_.evaluation, &summary, &gt_from_est);
    aligned = !summary.contains("evaluation_error");
    result.report.push_back("  " + line);
    if (aligned) {
      AddFrameMotionErrors(*ground_truth, estimate, gt_from_est.scale,
                           config_.evaluation.max_time_diff, out, &summary);
    }
  }
  if (comparison != nullptr) {
    summary["compare_solver"] = comparison->Summary(ground_truth, config_.evaluation);
    result.report.push_back("  " + comparison->Line(summary["compare_solver"]));
  }
  if (observer_ != nullptr) {
    observer_->AddToSummary(&summary);
    const std::string line = observer_->ReportLine();
    if (!line.empty()) result.report.push_back("  " + line);
  }
  {
    std::ofstream summary_file(out + "/summary.json");
    summary_file << summary.dump(2) << "\n";
    if (!summary_file) throw RunOutputError("cannot write " + out + "/summary.json");
  }
  try {
    WriteRunSvg(out + "/trajectory.svg", options_.dataset_label + " (top view)", ground_truth,
                estimate, aligned ? &gt_from_est : nullptr);
  } catch (const std::exception& e) {
    throw RunOutputError(e.what());
  }
  result.report.push_back("  outputs in " + out);
  return result;
}

void PrintRunReport(const SequenceRunResult& result, std::ostream& out) {
  for (size_t i = 0; i < result.report.size(); ++i) {
    out << (i == 0 ? "pldvo run: " : "") << result.report[i] << "\n";
  }
}

}  // namespace pldvo
