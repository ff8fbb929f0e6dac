#include "backend/odometry/odometry.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "backend/edge_ba/edge_ba_line_depth.h"
#include "backend/edge_ba/edge_ba_solver.h"
#include "backend/odometry/alternative_choice.h"
#include "backend/odometry/keyframe_selector.h"
#include "backend/odometry/reference_builder.h"
#include "core/wall_clock.h"

namespace pldvo {
namespace {

// Maps keyframe segments into the frame with the homography of cur_from_kf and the
// fronto-parallel plane at inverse depth `idepth` (z = 1 / idepth in the keyframe):
// H = K (R + t idepth e3^T) K^-1.
SegmentPredictor MakePredictor(const PinholeCamera& camera, const SE3& cur_from_kf, double idepth) {
  const Eigen::Matrix3d k = camera.K();
  Eigen::Matrix3d m = cur_from_kf.rotation_matrix();
  m.col(2) += idepth * cur_from_kf.translation();
  return PredictorFromHomography(k * m * k.inverse());
}

}  // namespace

const char* FrameStatusName(FrameStatus status) {
  switch (status) {
    case FrameStatus::kKeyframe:
      return "keyframe";
    case FrameStatus::kTracked:
      return "tracked";
    case FrameStatus::kRecovered:
      return "recovered";
    case FrameStatus::kLost:
      return "lost";
    case FrameStatus::kReinitialized:
      return "reinitialized";
    case FrameStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

Odometry::Odometry(const PinholeCamera& camera, const OdometryConfig& config,
                   OdometryObserver* observer)
    : camera_(camera),
      config_(config),
      observer_(observer),
      preparer_(config),
      tracker_(config.tracking),
      retry_trigger_(config.odometry.retry_rms_ratio) {
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) throw std::invalid_argument("Odometry: camera: " + camera_error);
  const std::string error = config.Check();
  if (!error.empty()) throw std::invalid_argument("Odometry: config: " + error);
  if (config_.odometry.use_lines) frontend_ = std::make_unique<LineFrontend>(config_.lines);
  if (config_.odometry.compare_solver != OdometryOptions::CompareSolver::kNone) {
    TrackingOptions compare = config_.tracking;
    compare.solver.type = config_.odometry.compare_solver == OdometryOptions::CompareSolver::kCeres
                              ? SolverOptions::Type::kCeres
                              : SolverOptions::Type::kGaussNewton;
    compare_tracker_ = std::make_unique<Tracker>(compare);
  }
  if (config_.odometry.use_lines && config_.odometry.line_consensus_max_cost_drop > 0.0) {
    consensus_ = std::make_unique<PhotometricConsensus>(
        config_.tracking, config_.odometry.line_consensus_max_cost_drop);
  }
  mapper_ = std::make_unique<MappingWorker>(
      camera_, config_.mapping, config_.odometry.parallel_mapping,
      config_.odometry.mapping_queue_size, config_.odometry.wait_for_mapping,
      config_.odometry.mapping_lag);
  const EdgeBAOptions& edge_ba = config_.backend.edge_ba;
  if (edge_ba.enabled) {
    edge_ba_window_ = std::make_unique<KeyframeWindow>(camera_, edge_ba.window,
                                                       edge_ba.max_pixels_per_observation);
    if (config_.odometry.parallel_mapping) {
      edge_ba_adjuster_ = std::make_unique<EdgeBundleAdjuster>(edge_ba);
    }
  }
  const WindowedBAOptions& windowed_ba = config_.backend.windowed_ba;
  if (windowed_ba.enabled) {
    windowed_ba_keyframes_ = std::make_unique<WindowedBAKeyframes>(
        camera_, windowed_ba.window, windowed_ba.leaving, windowed_ba.leaving_min_visible);
    if (config_.odometry.parallel_mapping) {
      windowed_ba_adjuster_ = std::make_unique<WindowedBundleAdjuster>(windowed_ba);
    }
  }
}

Odometry::~Odometry() = default;

OdometryStatistics Odometry::statistics() const {
  OdometryStatistics stats = stats_;
  stats.dropped_mapping_updates = mapper_->dropped_updates();
  stats.failed_mapping_jobs = mapper_->failed_jobs();
  stats.edge_ba_line_depths_fused = mapper_->line_depths_fused();
  stats.edge_ba_line_depth_outliers = mapper_->line_depth_outliers();
  stats.windowed_ba_idepths_corrected = mapper_->idepth_corrections_applied();
  return stats;
}

SE3 Odometry::PredictWorldFromCam(int index) const {
  const int frames = std::max(1, index - last_good_index_);
  return world_from_last_good_ * SE3::Exp(static_cast<double>(frames) * velocity_.Log());
}

void Odometry::CheckImage(int index, const cv::Mat& image) const {
  if (image.empty() || image.channels() != 1 || image.cols != camera_.width ||
      image.rows != camera_.height) {
    throw std::invalid_argument("Odometry::ProcessFrame: frame " + std::to_string(index) +
                                " is not a gray image of " + std::to_string(camera_.width) + "x" +
                                std::to_string(camera_.height));
  }
}

OdometryFrameResult Odometry::ProcessFrame(int index, double timestamp, const cv::Mat& image,
                                           const cv::Mat& depth) {
  CheckImage(index, image);
  const auto start = WallClock::now();
  PreparedFrame frame;
  try {
    frame = preparer_.Prepare(image);
  } catch (const std::exception& e) {
    return SkipFrame(index, timestamp, std::string("processing failed: ") + e.what());
  }
  return ProcessPrepared(index, timestamp, std::move(frame), depth, start);
}

OdometryFrameResult Odometry::ProcessFrame(int index, double timestamp, PreparedFrame frame,
                                           const cv::Mat& depth) {
  CheckImage(index, frame.image);
  if (frame.pyramid.num_levels() != config_.odometry.num_levels) {
    throw std::invalid_argument("Odometry::ProcessFrame: frame " + std::to_string(index) +
                                " was prepared with " + std::to_string(frame.pyramid.num_levels()) +
                                " pyramid levels, " + "odometry.num_levels is " +
                                std::to_string(config_.odometry.num_levels));
  }
  return ProcessPrepared(index, timestamp, std::move(frame), depth, WallClock::now());
}

OdometryFrameResult Odometry::ProcessPrepared(int index, double timestamp, PreparedFrame frame,
                                              const cv::Mat& depth, WallClock::time_point start) {
  OdometryFrameResult result;
  try {
    result = Process(index, timestamp, std::move(frame), depth);
  } catch (const std::exception& e) {
    return SkipFrame(index, timestamp, std::string("processing failed: ") + e.what());
  }
  result.timing.tracking_thread_ms = MsSince(start) - result.timing.compare_tracking_ms;
  return Finalize(std::move(result));
}

OdometryFrameResult Odometry::SkipFrame(int index, double timestamp, const std::string& reason) {
  OdometryFrameResult result;
  result.index = index;
  result.timestamp = timestamp;
  result.status = FrameStatus::kFailed;
  result.world_from_cam = initialized_ ? PredictWorldFromCam(index) : SE3();
  result.keyframe_id = keyframe_.id;
  result.message = reason;
  if (initialized_) {
    ++consecutive_lost_;
    recovering_ = true;
  }
  return Finalize(std::move(result));
}

OdometryFrameResult Odometry::Finalize(OdometryFrameResult result) {
  result.timing.mapping_ms = mapper_->TakeRecentJobMs();
  ++stats_.frames;
  stats_.line_term_drops += result.line_term_dropped;
  stats_.line_term_withheld += result.line_term_withheld;
  stats_.alternatives_gated += result.alternatives_gated > 0;
  const bool tracked = IsTracked(result.status);
  if (tracked) {
    ++stats_.tracked;
    // The first frame tracked on a fresh random map starts a new scale segment.
    if (scale_lost_) {
      ++stats_.scale_segments;
      scale_lost_ = false;
    }
  } else {
    ++stats_.lost_frames;
    // A lost event starts at the first non-tracked frame after a tracked one.
    if (last_index_ < 0 || last_tracked_) ++stats_.lost_events;
  }
  if (result.status == FrameStatus::kReinitialized) ++stats_.reinitializations;
  last_tracked_ = tracked;
  last_index_ = result.index;
  if (observer_ != nullptr) observer_->OnFrame(result);
  return result;
}

void Odometry::StartKeyframe(int index, double timestamp, const cv::Mat& image, LineFrame lines,
                             const SE3& world_from_cam, bool initialize, const SE3& new_from_old,
                             int min_propagated_points, OdometryTiming* timing,
                             const std::vector<int>* previous_segment, const cv::Mat& depth) {
  MappingJob job;
  job.kind = initialize ? MappingJob::Kind::kInitialize : MappingJob::Kind::kNewKeyframe;
  job.keyframe_id = next_keyframe_id_++;
  job.frame_index = index;
  job.image = image;
  // The new keyframe relative to the old one (its propagation's intensity test); the frames
  // after it start from the new keyframe's own brightness.
  job.brightness = brightness_;
  brightness_ = AffineBrightness();
  job.num_levels = config_.odometry.num_levels;
  job.new_from_old = new_from_old;
  job.min_propagated_points = min_propagated_points;
  if (initialize && config_.odometry.init_depth_idepth_var > 0.0 && !depth.empty()) {
    job.depth = depth;
    job.depth_idepth_var = config_.odometry.init_depth_idepth_var;
  }
  const bool want_maps = observer_ != nullptr && observer_->WantsKeyframeMaps();
  // The windowed BA records the retired keyframe's final map too.
  job.keep_retired_map = (want_maps || windowed_ba_keyframes_ != nullptr) && !initialize;
  const AffineBrightness brightness_from_previous = job.brightness;
  if (frontend_ != nullptr && !lines.segments.empty()) {
    // Every keyframe segment is traced: its pixels get an edge id in the map, and whichever of
    // them a later frame matches gives point-to-line residuals and line-guided stereo.
    std::vector<LineMatch> all(lines.segments.size());
    for (size_t i = 0; i < all.size(); ++i) all[i].ref_index = static_cast<int>(i);
    LineFrontendTiming trace_timing;
    job.edges = frontend_->TraceMatched(lines, all, &trace_timing);
    timing->tracing_ms += trace_timing.tracing_ms;
  }
  if (want_maps && !initialize) retiring_ = keyframe_;
  keyframe_ = ActiveKeyframe();
  keyframe_.id = job.keyframe_id;
  keyframe_.frame_index = index;
  keyframe_.timestamp = timestamp;
  keyframe_.world_from_kf = world_from_cam;
  keyframe_.image = image;
  keyframe_.lines = std::move(lines);
  ++stats_.keyframes;
  // The keyframe job goes first: a result applied in UpdateEdgeBA may send line depths for it.
  const EdgeTrace edges = edge_ba_window_ != nullptr ? job.edges : EdgeTrace();
  mapper_->Submit(std::move(job));
  if (edge_ba_window_ != nullptr) UpdateEdgeBA(edges, previous_segment, new_from_old.Inverse());
  if (windowed_ba_keyframes_ != nullptr) {
    // Not associated with the previous keyframe (first keyframe, re-initialisation at an
    // extrapolated pose): the window restarts with this keyframe.
    if (previous_segment == nullptr) windowed_ba_keyframes_->Clear();
    windowed_ba_keyframes_->AddKeyframe(
        keyframe_.id, index, timestamp, keyframe_.world_from_kf, image, keyframe_.lines.segments,
        previous_segment != nullptr ? *previous_segment : std::vector<int>(),
        brightness_from_previous);
  }
}

void Odometry::UpdateWindowedBA(const KeyframeMap& map) {
  if (map.retired_map != nullptr) {
    windowed_ba_keyframes_->SetPoints(map.retired_keyframe_id, *map.retired_map);
  }
  if (map.map == nullptr || map.keyframe_id != keyframe_.id ||
      !windowed_ba_keyframes_->SetPoints(map.keyframe_id, *map.map) ||
      !windowed_ba_keyframes_->Ready()) {
    return;
  }
  WindowedBAWindow window = windowed_ba_keyframes_->MakeWindow();
  window.intensity_noise_sigma = intensity_noise_sigma_;
  try {
    if (windowed_ba_adjuster_ != nullptr) {
      // Remember reads the ids and poses only; the adjuster gets the points.
      WindowedBAWindow submitted;
      for (const WindowedBAKeyframe& k : window.keyframes) {
        submitted.keyframes.push_back({k.id, k.cam_from_world, k.brightness, nullptr, {}, {}});
      }
      windowed_ba_keyframes_->Remember(windowed_ba_adjuster_->Submit(std::move(window)), submitted);
      return;
    }
    windowed_ba_keyframes_->Remember(-1, window);
    ApplyWindowedBA(RunWindowedBA(window, config_.backend.windowed_ba));  // sequence -1
  } catch (const std::exception& e) {
    // A malformed window (CheckWindowedBAWindow) or a failed build: the run goes on without it.
    LOG(WARNING) << "windowed BA at keyframe " << keyframe_.id << " failed: " << e.what();
    ++stats_.windowed_ba_failures;
  }
}

void Odometry::PollWindowedBA() {
  if (windowed_ba_adjuster_ == nullptr) return;
  while (std::optional<WindowedBAResult> result = windowed_ba_adjuster_->Poll()) {
    ApplyWindowedBA(*result);
  }
}

void Odometry::ApplyWindowedBA(const WindowedBAResult& result) {
  ++stats_.windowed_ba_windows;
  windowed_ba_times_ms_.push_back(
      1e3 * (result.build_seconds + result.solve_seconds + result.marginalize_seconds));
  if (result.num_prior_keyframes > 0) ++stats_.windowed_ba_prior_windows;
  windowed_ba_points_.push_back(static_cast<double>(result.points.size()));
  windowed_ba_iterations_.push_back(result.summary.iterations);
  windowed_ba_outlier_targets_.push_back(static_cast<double>(result.num_outlier_targets));
  // The current keyframe relative to the keyframe its map was propagated from, before the result.
  SE3 world_from_previous;
  const bool has_previous =
      windowed_ba_keyframes_->WorldFromPreviousKeyframe(keyframe_.id, &world_from_previous);
  const SE3 kf_from_previous_before = keyframe_.world_from_kf.Inverse() * world_from_previous;
  std::vector<IdepthCorrection> corrections;
  double idepth_scale = 1.0;
  if (!windowed_ba_keyframes_->Apply(result, keyframe_.id, &corrections, &idepth_scale)) return;
  ++stats_.windowed_ba_applied;
  SE3 world_from_kf;
  if (windowed_ba_keyframes_->WorldFromKeyframe(keyframe_.id, &world_from_kf)) {
    MoveCurrentKeyframe(world_from_kf);
  }
  if (retiring_.id >= 0) {
    windowed_ba_keyframes_->WorldFromKeyframe(retiring_.id, &retiring_.world_from_kf);
  }
  if (!config_.backend.windowed_ba.depth_feedback) return;
  // The current keyframe's hypotheses (the mapping thread ignores the job once the keyframe is
  // no longer current): the optimised points' corrections and, with warp_current_map, the others
  // re-expressed in the keyframe's frame as moved relative to the keyframe its map was propagated
  // from (tracking of the next frames uses the whole map with the moved pose).
  MappingJob job;
  job.kind = MappingJob::Kind::kIdepthCorrections;
  job.keyframe_id = keyframe_.id;
  job.frame_index = keyframe_.frame_index;
  job.idepth_corrections = std::move(corrections);
  if (has_previous && config_.backend.windowed_ba.warp_current_map &&
      windowed_ba_keyframes_->WorldFromPreviousKeyframe(keyframe_.id, &world_from_previous)) {
    const SE3 kf_from_previous_after = keyframe_.world_from_kf.Inverse() * world_from_previous;
    job.move_keyframe = true;
    job.new_from_old = kf_from_previous_after * kf_from_previous_before.Inverse();
  }
  if (config_.backend.windowed_ba.scale_current_map && idepth_scale != 1.0) {
    job.idepth_scale = idepth_scale;
    ScaleCurrentKeyframeMap(idepth_scale);
  }
  if (job.idepth_corrections.empty() && !job.move_keyframe && job.idepth_scale == 1.0) return;
  ++stats_.windowed_ba_idepth_jobs;
  mapper_->Submit(std::move(job));
}

std::vector<KeyframePoseRecord> Odometry::WindowedBAKeyframePoses() const {
  if (windowed_ba_keyframes_ == nullptr) return {};
  std::vector<KeyframePoseRecord> poses = windowed_ba_keyframes_->Departed();
  const std::vector<KeyframePoseRecord> recorded = windowed_ba_keyframes_->Recorded();
  poses.insert(poses.end(), recorded.begin(), recorded.end());
  // Keyframes may leave out of order (backend.windowed_ba.leaving); the output is in time order.
  std::stable_sort(
      poses.begin(), poses.end(),
      [](const KeyframePoseRecord& a, const KeyframePoseRecord& b) { return a.id < b.id; });
  return poses;
}

void Odometry::UpdateEdgeBA(const EdgeTrace& edges, const std::vector<int>* previous_segment,
                            const SE3& old_from_new) {
  if (previous_segment == nullptr) {
    edge_ba_window_->Clear();
    edge_ba_window_->AddKeyframe(keyframe_.id, keyframe_.world_from_kf, edges, {}, nullptr);
    return;
  }
  edge_ba_window_->AddKeyframe(keyframe_.id, keyframe_.world_from_kf, edges, *previous_segment,
                               &old_from_new);
  if (edge_ba_window_->size() < 2) return;
  EdgeBAWindow window = edge_ba_window_->MakeWindow();
  if (edge_ba_adjuster_ != nullptr) {
    // The adjuster gets a copy; `window` keeps the submitted poses for the result.
    edge_ba_window_->Remember(edge_ba_adjuster_->Submit(window), window);
    return;
  }
  edge_ba_window_->Remember(-1, window);
  ApplyEdgeBA(SolveEdgeBA(window, config_.backend.edge_ba));  // sequence -1
}

void Odometry::PollEdgeBA() {
  if (edge_ba_adjuster_ == nullptr) return;
  while (std::optional<EdgeBAResult> result = edge_ba_adjuster_->Poll()) ApplyEdgeBA(*result);
}

void Odometry::MoveCurrentKeyframe(const SE3& world_from_kf) {
  world_from_last_good_ = world_from_kf * keyframe_.world_from_kf.Inverse() * world_from_last_good_;
  keyframe_.world_from_kf = world_from_kf;
}

void Odometry::ScaleCurrentKeyframeMap(double idepth_scale) {
  // Inverse depths times s: lengths in the keyframe's frame divided by s, so the last tracked
  // frame's translation relative to it and the motion model's translation too.
  const SE3 kf_from_last = keyframe_.world_from_kf.Inverse() * world_from_last_good_;
  world_from_last_good_ = keyframe_.world_from_kf * SE3(kf_from_last.rotation_matrix(),
                                                        kf_from_last.translation() / idepth_scale);
  velocity_ = SE3(velocity_.rotation_matrix(), velocity_.translation() / idepth_scale);
}

void Odometry::ApplyEdgeBA(const EdgeBAResult& result) {
  ++stats_.edge_ba_windows;
  edge_ba_times_ms_.push_back(1e3 * (result.build_seconds + result.solve_seconds));
  if (result.covariance_seconds > 0.0) {
    edge_ba_covariance_ms_.push_back(1e3 * result.covariance_seconds);
  }
  if (!edge_ba_window_->Apply(result)) return;
  ++stats_.edge_ba_applied;
  SE3 world_from_kf;
  if (edge_ba_window_->WorldFromKeyframe(keyframe_.id, &world_from_kf)) {
    MoveCurrentKeyframe(world_from_kf);
  }
  if (retiring_.id >= 0) edge_ba_window_->WorldFromKeyframe(retiring_.id, &retiring_.world_from_kf);
  if (config_.backend.edge_ba.line_depth_feedback) SendLineDepths(result);
}

void Odometry::SendLineDepths(const EdgeBAResult& result) {
  if (!result.covariance_ok) {
    // Nothing to send without optimised lines; otherwise ceres::Covariance failed.
    if (result.num_optimized_lines > 0) ++stats_.edge_ba_covariance_failures;
    return;
  }
  // Only the current keyframe: the mapping thread holds no other map (older keyframes' maps are
  // retired). Its segments associated with an optimised line, in its (refined) camera frame.
  std::map<int, const EdgeBAResultLine*> optimized;
  for (const EdgeBAResultLine& line : result.lines) {
    if (line.status == EdgeBALineStatus::kOptimized && line.has_covariance) {
      optimized[line.line.id] = &line;
    }
  }
  const SE3 kf_from_world = keyframe_.world_from_kf.Inverse();
  MappingJob job;
  job.kind = MappingJob::Kind::kLineDepths;
  job.keyframe_id = keyframe_.id;
  job.frame_index = keyframe_.frame_index;
  for (const auto& [segment, line_id] : edge_ba_window_->LinesOfKeyframe(keyframe_.id)) {
    const auto it = optimized.find(line_id);
    if (it == optimized.end()) continue;
    const EdgeBALine& line = it->second->line;
    job.line_depths.push_back(LineInCamera(kf_from_world, line.point_in_world,
                                           line.direction_in_world, it->second->tangent_covariance,
                                           segment));
  }
  if (job.line_depths.empty()) return;
  ++stats_.edge_ba_line_depth_jobs;
  mapper_->Submit(std::move(job));
}

void Odometry::NotifyRetired(const KeyframeMap& map) {
  if (observer_ == nullptr || retiring_.id < 0 || map.retired_map == nullptr ||
      map.retired_keyframe_id != retiring_.id) {
    return;
  }
  KeyframeInfo info;
  info.keyframe_id = retiring_.id;
  info.frame_index = retiring_.frame_index;
  info.timestamp = retiring_.timestamp;
  info.world_from_kf = retiring_.world_from_kf;
  info.image = retiring_.image;
  info.camera = camera_;
  observer_->OnKeyframeFinished(info, *map.retired_map);
  retiring_ = ActiveKeyframe();
}

void Odometry::NoteKeyframeMap(const KeyframeMap& map) {
  if (map.keyframe_id <= last_noted_keyframe_id_) return;
  last_noted_keyframe_id_ = map.keyframe_id;
  // Only a re-initialisation sets random_init on a later keyframe (MappingWorker: kNewKeyframe
  // with min_propagated_points); the map then has an arbitrary scale of its own.
  if (map.keyframe_id != first_keyframe_id_ && map.random_init) scale_lost_ = true;
}

void Odometry::RefreshMap(OdometryTiming* timing) {
  const bool keyframe_changed = map_ == nullptr || map_->keyframe_id != keyframe_.id;
  const auto start = WallClock::now();
  map_ = mapper_->MapForTracking(keyframe_.id);
  timing->wait_ms += MsSince(start);
  if (!keyframe_changed || map_ == nullptr) return;
  NotifyRetired(*map_);
  NoteKeyframeMap(*map_);
  if (windowed_ba_keyframes_ != nullptr) {
    UpdateWindowedBA(*map_);
    // Synchronous: the depth corrections of the current keyframe are already published.
    if (windowed_ba_adjuster_ == nullptr) {
      const std::shared_ptr<const KeyframeMap> latest = mapper_->Latest();
      if (latest != nullptr && latest->keyframe_id == map_->keyframe_id) map_ = latest;
    }
  }
}

TrackingResult Odometry::TrackWithAlternatives(const ImagePyramid& pyramid, const cv::Mat& image,
                                               int index, const SE3& prior_cur_from_kf,
                                               const SE3& last_good_cur_from_kf,
                                               OdometryFrameResult* frame_result) {
  TrackingIterationCallback callback;
  if (observer_ != nullptr && observer_->WantsTrackingIterations(index)) {
    callback = [this, index, &image](const TrackingIteration& iteration) {
      observer_->OnTrackingIteration(index, image, iteration);
    };
  }
  TrackingResult best =
      tracker_.Track(reference_, pyramid, prior_cur_from_kf, brightness_, callback);
  frame_result->alternatives_tried = 1;
  const OdometryOptions& options = config_.odometry;
  if (!options.try_alternatives || !retry_trigger_.ShouldRetry(best)) return best;
  const double angle = options.alternative_rotation_deg * M_PI / 180.0;
  std::vector<SE3> guesses = {last_good_cur_from_kf};
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()};
  for (const Eigen::Vector3d& axis : axes) {
    for (const double sign : {1.0, -1.0}) {
      guesses.push_back(SE3(ExpSO3(sign * angle * axis), Eigen::Vector3d::Zero()) *
                        last_good_cur_from_kf);
    }
  }
  const TrackingResult first = best;
  const SE3 prior_step = prior_cur_from_kf * last_good_cur_from_kf.Inverse();
  for (const SE3& guess : guesses) {
    TrackingResult result = tracker_.Track(reference_, pyramid, guess, brightness_, callback);
    ++frame_result->alternatives_tried;
    if (!BetterAlternative(result, best, options.alternative_choice)) continue;
    if (AlternativeMayCompete(result, first, prior_step, map_->mean_idepth,
                              options.alternative_choice)) {
      best = std::move(result);
    } else {
      ++frame_result->alternatives_gated;
    }
  }
  return best;
}

OdometryFrameResult Odometry::Process(int index, double timestamp, PreparedFrame frame,
                                      const cv::Mat& depth) {
  OdometryFrameResult result;
  result.index = index;
  result.timestamp = timestamp;
  OdometryTiming& timing = result.timing;
  LineFrame& lines = frame.lines;
  timing.pyramid_ms = frame.pyramid_ms;
  timing.detection_ms = lines.timing.detection_ms + lines.timing.merging_ms;
  timing.description_ms = lines.timing.description_ms;
  result.num_lines = static_cast<int>(lines.segments.size());

  if (!initialized_) {
    StartFirstKeyframe(index, timestamp, frame.image, std::move(lines), depth, &result);
    return result;
  }
  PollEdgeBA();
  PollWindowedBA();
  RefreshMap(&timing);
  result.keyframe_id = keyframe_.id;
  const SE3 world_from_prior = PredictWorldFromCam(index);
  const SE3 prior_cur_from_kf = world_from_prior.Inverse() * keyframe_.world_from_kf;
  const bool have_map = map_ != nullptr && map_->keyframe_id == keyframe_.id &&
                        map_->reference != nullptr && map_->num_points > 0;
  if (!have_map) {
    result.message = "keyframe map has no points";
    HandleLostFrame(index, timestamp, frame.image, std::move(lines), world_from_prior,
                    prior_cur_from_kf, &result);
    return result;
  }
  result.num_reference_points = map_->num_points;
  result.mean_idepth = map_->mean_idepth;
  LineAssociation association = MatchKeyframeLines(&lines, prior_cur_from_kf, &result);
  // A map in its first stereo updates after a random initialisation holds mostly depth draws,
  // not measurements: its point-to-line rows would fit each matched edge's random parallax
  // (odometry.random_map_warmup_updates).
  result.line_term_withheld =
      result.num_matches > 0 && map_->updates_since_random_init >= 0 &&
      map_->updates_since_random_init < config_.odometry.random_map_warmup_updates;
  UpdateReference(result.line_term_withheld ? std::vector<MatchedLine>() : association.lines_in_cur,
                  &timing);
  TrackingResult tracking =
      TrackFrame(frame.pyramid, frame.image, index, prior_cur_from_kf, &association, &result);
  // A frame whose line term the consensus check dropped keeps a photometric-only solve, not the
  // tracking problem the other solver would solve: it is not compared.
  if (compare_tracker_ != nullptr && tracking.status != TrackingStatus::kLost &&
      !result.line_term_dropped) {
    CompareSolvers(frame.pyramid, tracking, &result);
  }
  if (tracking.status == TrackingStatus::kLost) {
    result.message = "tracking lost (valid residuals " + std::to_string(tracking.valid_residuals) +
                     ", inlier fraction " + std::to_string(tracking.inlier_fraction) +
                     ", intensity correlation " + std::to_string(tracking.intensity_correlation) +
                     ")";
    result.tracking = std::move(tracking);
    HandleLostFrame(index, timestamp, frame.image, std::move(lines), world_from_prior,
                    prior_cur_from_kf, &result);
    return result;
  }
  AcceptTrackedFrame(index, tracking, &result);
  MapOrSwitchKeyframe(index, timestamp, frame.image, std::move(lines), tracking,
                      std::move(association), &result);
  result.tracking = std::move(tracking);
  return result;
}

void Odometry::StartFirstKeyframe(int index, double timestamp, const cv::Mat& image,
                                  LineFrame lines, const cv::Mat& depth,
                                  OdometryFrameResult* result) {
  StartKeyframe(index, timestamp, image, std::move(lines), SE3(), true, SE3(), 0, &result->timing,
                nullptr, depth);
  initialized_ = true;
  first_keyframe_id_ = keyframe_.id;
  stats_.scale_segments = 1;
  world_from_last_good_ = SE3();
  last_good_index_ = index;
  velocity_ = SE3();
  result->status = FrameStatus::kKeyframe;
  result->keyframe_id = keyframe_.id;
}

Odometry::LineAssociation Odometry::MatchKeyframeLines(LineFrame* lines,
                                                       const SE3& prior_cur_from_kf,
                                                       OdometryFrameResult* result) {
  LineAssociation association;
  if (frontend_ == nullptr || keyframe_.lines.segments.empty() || lines->segments.empty()) {
    return association;
  }
  const SegmentPredictor predictor =
      config_.odometry.predict_line_matches
          ? MakePredictor(camera_, prior_cur_from_kf, map_->mean_idepth)
          : SegmentPredictor();
  LineFrontendTiming match_timing;
  association.matches = frontend_->Match(&keyframe_.lines, lines, predictor, &match_timing);
  result->timing.matching_ms = match_timing.matching_ms;
  result->timing.description_ms += match_timing.description_ms;
  result->num_matches = static_cast<int>(association.matches.size());
  association.lines_in_cur = MatchedLinesFromMatches(
      association.matches, lines->segments, static_cast<int>(keyframe_.lines.segments.size()));
  return association;
}

void Odometry::UpdateReference(const std::vector<MatchedLine>& lines_in_cur,
                               OdometryTiming* timing) {
  const auto start = WallClock::now();
  if (reference_source_ != map_->reference.get()) {
    reference_ = *map_->reference;
    reference_source_ = map_->reference.get();
  }
  SetMatchedLines(lines_in_cur, &reference_);
  reference_.intensity_noise_sigma = intensity_noise_sigma_;
  reference_.line_noise_scale = line_noise_scale_;
  timing->reference_ms = MsSince(start);
}

TrackingResult Odometry::TrackFrame(const ImagePyramid& pyramid, const cv::Mat& image, int index,
                                    const SE3& prior_cur_from_kf, LineAssociation* association,
                                    OdometryFrameResult* result) {
  const auto start = WallClock::now();
  const SE3 last_good_cur_from_kf = world_from_last_good_.Inverse() * keyframe_.world_from_kf;
  const bool line_term = result->num_matches > 0 && !result->line_term_withheld;
  // Gate the matches around their prediction by the prior, track, then drop the matches that
  // disagree with the tracked pose and track again from it.
  if (config_.odometry.line_prior_gate_px > 0.0 && line_term) {
    result->num_line_outliers =
        RemoveLineOutliers(prior_cur_from_kf, config_.odometry.line_prior_gate_px, &reference_,
                           &association->lines_in_cur);
  }
  TrackingResult tracking = TrackWithAlternatives(pyramid, image, index, prior_cur_from_kf,
                                                  last_good_cur_from_kf, result);
  if (config_.odometry.line_outlier_px > 0.0 && line_term &&
      tracking.status != TrackingStatus::kLost) {
    const int outliers = RemoveLineOutliers(tracking.cur_from_ref, config_.odometry.line_outlier_px,
                                            &reference_, &association->lines_in_cur);
    result->num_line_outliers += outliers;
    if (outliers > 0) {
      TrackingResult again =
          config_.odometry.line_outlier_refine_finest
              ? tracker_.Refine(reference_, pyramid, tracking.cur_from_ref, tracking.brightness)
              : tracker_.Track(reference_, pyramid, tracking.cur_from_ref, tracking.brightness);
      if (again.status != TrackingStatus::kLost) tracking = std::move(again);
    }
  }
  if (consensus_ != nullptr && line_term && tracking.status != TrackingStatus::kLost) {
    const auto consensus_start = WallClock::now();
    std::optional<TrackingResult> photometric = consensus_->Check(reference_, pyramid, tracking);
    result->timing.consensus_ms = MsSince(consensus_start);
    if (photometric) {
      tracking = std::move(*photometric);
      result->line_term_dropped = true;
    }
  }
  result->timing.tracking_ms = MsSince(start);
  return tracking;
}

void Odometry::CompareSolvers(const ImagePyramid& pyramid, const TrackingResult& tracking,
                              OdometryFrameResult* result) {
  const auto start = WallClock::now();
  // The same solve from the same start. One level solved: a refinement after unmatching lines,
  // or a track whose coarsest level is the finest (Refine solves the same); else coarse to fine.
  const TrackingResult other =
      tracking.levels.size() == 1
          ? compare_tracker_->Refine(reference_, pyramid, tracking.initial_cur_from_ref,
                                     tracking.initial_brightness)
          : compare_tracker_->Track(reference_, pyramid, tracking.initial_cur_from_ref,
                                    tracking.initial_brightness);
  result->timing.compare_tracking_ms = MsSince(start);
  result->compared = true;
  result->compared_status = other.status;
  result->world_from_cam_compared = keyframe_.world_from_kf * other.cur_from_ref.Inverse();
  if (!other.levels.empty()) {
    result->compared_initial_cost = other.levels.back().initial_cost;
    result->compared_final_cost = other.levels.back().final_cost;
  }
  result->compared_valid_residuals = other.valid_residuals;
}

void Odometry::AcceptTrackedFrame(int index, const TrackingResult& tracking,
                                  OdometryFrameResult* result) {
  const SE3 world_from_cur = keyframe_.world_from_kf * tracking.cur_from_ref.Inverse();
  // Constant-velocity motion model over the frames since the last good one.
  const int frames = std::max(1, index - last_good_index_);
  velocity_ = SE3::Exp((world_from_last_good_.Inverse() * world_from_cur).Log() /
                       static_cast<double>(frames));
  world_from_last_good_ = world_from_cur;
  last_good_index_ = index;
  brightness_ = tracking.brightness;
  if (tracking.intensity_noise_sigma > 0.0) intensity_noise_sigma_ = tracking.intensity_noise_sigma;
  if (tracking.line_noise_scale > 0.0) line_noise_scale_ = tracking.line_noise_scale;
  retry_trigger_.Update(tracking);
  result->world_from_cam = world_from_cur;
  result->status = recovering_ ? FrameStatus::kRecovered : FrameStatus::kTracked;
  consecutive_lost_ = 0;
  recovering_ = false;
  ++keyframe_.frames_tracked;
}

void Odometry::MapOrSwitchKeyframe(int index, double timestamp, const cv::Mat& image,
                                   LineFrame lines, const TrackingResult& tracking,
                                   LineAssociation association, OdometryFrameResult* result) {
  OdometryTiming& timing = result->timing;
  const SE3& cur_from_kf = tracking.cur_from_ref;
  const auto start = WallClock::now();
  const int overlap_level = std::min(2, reference_.num_levels() - 1);
  const double overlap = ReferenceOverlap(reference_, overlap_level, cur_from_kf);
  timing.reference_ms += MsSince(start);
  // The keyframe's photometric misfit in gray levels: the image noise the frame's errors imply
  // (a whitened RMS would be relative to the previous frame's estimated sigma_I), else the RMS.
  const double rms = tracking.intensity_noise_sigma > 0.0 ? tracking.intensity_noise_sigma
                                                          : RetryTrigger::Rms(tracking);
  if (rms > 0.0 && (keyframe_.min_rms == 0.0 || rms < keyframe_.min_rms)) keyframe_.min_rms = rms;
  KeyframeEvidence evidence;
  evidence.cur_from_kf = cur_from_kf;
  evidence.mean_idepth = map_->mean_idepth;
  evidence.overlap = overlap;
  evidence.inlier_fraction = tracking.inlier_fraction;
  evidence.rms_growth = keyframe_.min_rms > 0.0 ? rms / keyframe_.min_rms : 1.0;
  evidence.frames_tracked = keyframe_.frames_tracked;
  const KeyframeDecision decision = DecideKeyframe(config_.keyframes, evidence);
  if (decision.new_keyframe) {
    // The new keyframe's segments that the verified matches tie to the old keyframe's.
    std::vector<int> previous_segment(lines.segments.size(), -1);
    for (const LineMatch& match : association.matches) {
      if (association.lines_in_cur[match.ref_index].matched) {
        previous_segment[match.cur_index] = match.ref_index;
      }
    }
    StartKeyframe(index, timestamp, image, std::move(lines), result->world_from_cam, false,
                  cur_from_kf, 0, &timing, &previous_segment);
    // Synchronous edge BA may have refined the new keyframe's pose.
    result->world_from_cam = keyframe_.world_from_kf;
    result->status = FrameStatus::kKeyframe;
    result->keyframe_id = keyframe_.id;
    result->message = "new keyframe: " + decision.reason;
    return;
  }
  MappingJob job;
  job.kind = MappingJob::Kind::kUpdate;
  job.keyframe_id = keyframe_.id;
  job.frame_index = index;
  job.image = image;
  job.cur_from_kf = cur_from_kf;
  job.pose_covariance = tracking.pose_covariance;
  job.brightness = brightness_;
  job.lines_in_cur = std::move(association.lines_in_cur);
  if (config_.mapping.line_stereo_estimated_line_noise && line_noise_scale_ > 0.0) {
    job.line_cov_scale = line_noise_scale_ * line_noise_scale_;
  }
  mapper_->Submit(std::move(job));
}

void Odometry::HandleLostFrame(int index, double timestamp, const cv::Mat& image, LineFrame lines,
                               const SE3& world_from_prior, const SE3& prior_cur_from_kf,
                               OdometryFrameResult* result) {
  // Lost: extrapolate; after reinit_after_lost consecutive lost frames restart at this frame.
  result->world_from_cam = world_from_prior;
  result->status = FrameStatus::kLost;
  ++consecutive_lost_;
  recovering_ = true;
  if (consecutive_lost_ < config_.odometry.reinit_after_lost) return;
  // Not associated with the old keyframe (an extrapolated pose): the edge BA window restarts.
  StartKeyframe(index, timestamp, image, std::move(lines), world_from_prior, false,
                prior_cur_from_kf, config_.odometry.reinit_min_points, &result->timing, nullptr);
  world_from_last_good_ = world_from_prior;
  last_good_index_ = index;
  consecutive_lost_ = 0;
  result->status = FrameStatus::kReinitialized;
  result->keyframe_id = keyframe_.id;
  result->message += "; re-initialised at this frame";
}

void Odometry::Finish() {
  mapper_->Flush();
  if (edge_ba_adjuster_ != nullptr) {
    edge_ba_adjuster_->WaitIdle();
    PollEdgeBA();
  }
  if (windowed_ba_adjuster_ != nullptr) {
    windowed_ba_adjuster_->WaitIdle();
    PollWindowedBA();
  }
  if (observer_ == nullptr || !observer_->WantsKeyframeMaps() || keyframe_.id < 0) return;
  const std::shared_ptr<const KeyframeMap> map = mapper_->Latest();
  if (map == nullptr) return;
  NotifyRetired(*map);
  if (map->keyframe_id != keyframe_.id || map->map == nullptr) return;
  KeyframeInfo info;
  info.keyframe_id = keyframe_.id;
  info.frame_index = keyframe_.frame_index;
  info.timestamp = keyframe_.timestamp;
  info.world_from_kf = keyframe_.world_from_kf;
  info.image = keyframe_.image;
  info.camera = camera_;
  observer_->OnKeyframeFinished(info, *map->map);
}

}  // namespace pldvo
