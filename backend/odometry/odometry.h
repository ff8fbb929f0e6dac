// Frame-to-keyframe monocular odometry with points and lines (Yang & Scherer, ICRA 2017, on
// Engel et al.'s semi-dense VO): what `pldvo run` drives. See docs/odometry.md.
//
// Per frame (ProcessFrame, on the caller's thread):
//   1. image pyramid; line detection, merging and LBD (frontend/line_frontend.h); a pure function
//      of the image (FramePreparer), which a driver may run ahead on another thread;
//   2. the keyframe's latest map (MappingWorker); keyframe lines matched into the frame, gated
//      around their prediction by the pose prior;
//   3. the tracking reference: the map's points per level (reference_builder.h) with the matched
//      current lines;
//   4. coarse-to-fine tracking (backend/tracking/tracker.h) from the constant-velocity prior; when
//   lost or
//      the RMS stays high, alternative initial guesses (zero motion, small rotations);
//   5. tracked: the keyframe criteria (keyframe_selector.h) either queue a depth-filter update
//      with the frame or make it the new keyframe (its edges traced, the map propagated);
//      lost: the pose is extrapolated, and after odometry.reinit_after_lost consecutive lost
//      frames the frame becomes a keyframe at the extrapolated pose (propagated or fresh map).
// The first frame is a keyframe with a random inverse-depth map of large variance (monocular
// initialisation; the scale is arbitrary). Mapping runs in its own thread unless
// odometry.parallel_mapping is false (deterministic).
// With backend.edge_ba.enabled, every new keyframe (after the first) submits the window of the
// newest keyframes (KeyframeWindow) to windowed edge bundle adjustment: on EdgeBundleAdjuster's
// worker thread, polled at the start of every frame, or synchronously at the keyframe when
// odometry.parallel_mapping is false (deterministic). A result moves the window keyframes'
// world_from_kf, and with it the current keyframe and the motion model; with
// backend.edge_ba.line_depth_feedback, the optimised lines the current keyframe observes go to
// the mapping thread and are fused into its depth map (docs/edge_ba.md).
// With backend.windowed_ba.enabled, every keyframe is recorded (WindowedBAKeyframes) and, when the
// mapping thread has published a new keyframe's first map (with the previous keyframe's final
// one), the newest keyframes are submitted to windowed photometric + line bundle adjustment: on
// WindowedBundleAdjuster's worker thread, polled at the start of every frame, or synchronously
// when odometry.parallel_mapping is false (deterministic). A result moves the window keyframes'
// world_from_kf, the current keyframe and the motion model with them, and shifts the current
// keyframe's depth-filter hypotheses by the optimised points' corrections (docs/windowed_ba.md).
#ifndef PLDVO_BACKEND_ODOMETRY_ODOMETRY_H_
#define PLDVO_BACKEND_ODOMETRY_ODOMETRY_H_

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "backend/edge_ba/edge_ba_adjuster.h"
#include "backend/odometry/frame_preparer.h"
#include "backend/odometry/keyframe_window.h"
#include "backend/odometry/mapping_worker.h"
#include "backend/odometry/odometry_config.h"
#include "backend/odometry/odometry_observer.h"
#include "backend/odometry/retry_trigger.h"
#include "backend/odometry/windowed_ba_keyframes.h"
#include "backend/tracking/photometric_consensus.h"
#include "backend/tracking/tracker.h"
#include "backend/windowed_ba/windowed_ba_adjuster.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "core/wall_clock.h"
#include "frontend/line_frontend.h"

namespace pldvo {

struct OdometryStatistics {
  int frames = 0;
  int tracked = 0;  // IsTracked(status)
  int keyframes = 0;
  int lost_frames = 0;  // lost, reinitialized or failed
  int lost_events = 0;  // maximal runs of consecutive non-tracked frames
  int reinitializations = 0;
  // Pieces of the trajectory with one consistent scale: 1 from the first keyframe, plus one per
  // re-initialisation whose keyframe got a fresh random map (fewer than
  // odometry.reinit_min_points hypotheses survived the propagation), counted at the first frame
  // tracked after it. A re-initialisation that keeps the propagated map stays in the segment.
  int scale_segments = 0;
  int dropped_mapping_updates = 0;
  int failed_mapping_jobs = 0;
  int edge_ba_windows = 0;  // edge BA windows solved
  int edge_ba_applied = 0;  // ... whose result moved the keyframe poses
  // backend.edge_ba.line_depth_feedback: applied windows with optimised lines whose line
  // covariances failed (no feedback), line-depth jobs sent to the mapping thread, and the pixels
  // they fused / rejected.
  int edge_ba_covariance_failures = 0;
  int edge_ba_line_depth_jobs = 0;
  int edge_ba_line_depths_fused = 0;
  int edge_ba_line_depth_outliers = 0;
  int line_term_drops = 0;     // frames whose line term the consensus check dropped
  int line_term_withheld = 0;  // frames tracked without it (random_map_warmup_updates)
  int alternatives_gated = 0;  // frames where the motion gate kept out a winning alternative
  // backend.windowed_ba: windows solved, applied (moved the keyframe poses), solves that threw,
  // depth-correction jobs sent to the mapping thread and the hypotheses they shifted, windows
  // solved with a marginalisation prior (marginalize).
  int windowed_ba_windows = 0;
  int windowed_ba_applied = 0;
  int windowed_ba_failures = 0;
  int windowed_ba_idepth_jobs = 0;
  int windowed_ba_idepths_corrected = 0;
  int windowed_ba_prior_windows = 0;
};

class Odometry {
 public:
  // Throws std::invalid_argument when the config or camera is invalid. `observer` may be null
  // and must outlive the odometry.
  Odometry(const PinholeCamera& camera, const OdometryConfig& config,
           OdometryObserver* observer = nullptr);
  ~Odometry();

  // Processes the next frame (image CV_32F or CV_8U of the camera's size). Frames must come in
  // increasing index order. Throws std::invalid_argument on a wrong image size; any other failure
  // inside is caught and returned as a kFailed frame.
  // `depth` (CV_32F z-depth in metres, optional) is used only for the first keyframe and only
  // when odometry.init_depth_idepth_var > 0.
  OdometryFrameResult ProcessFrame(int index, double timestamp, const cv::Mat& image,
                                   const cv::Mat& depth = cv::Mat());
  // The same with the per-image work already done (FramePreparer with this odometry's config,
  // e.g. on another thread); the result is identical, and tracking_thread_ms leaves out the
  // preparation. Also throws std::invalid_argument when the pyramid's level count is not
  // odometry.num_levels.
  OdometryFrameResult ProcessFrame(int index, double timestamp, PreparedFrame frame,
                                   const cv::Mat& depth = cv::Mat());
  // A frame that could not be loaded: kFailed with the extrapolated pose.
  OdometryFrameResult SkipFrame(int index, double timestamp, const std::string& reason);
  // Waits for the mapping thread and reports the last keyframe's map to the observer.
  void Finish();

  OdometryStatistics statistics() const;
  // Wall time of every mapping job (ms), for the summary.
  std::vector<double> MappingJobTimesMs() const { return mapper_->JobTimesMs(); }
  // The mapping's stereo counts summed over the run (MappingWorker::stereo_counts).
  FrameUpdateStats StereoCounts() const { return mapper_->stereo_counts(); }
  // Wall time of every solved edge BA window (problem build + solve on the solving thread, ms).
  const std::vector<double>& EdgeBAWindowTimesMs() const { return edge_ba_times_ms_; }
  // Wall time of the line covariances of every window that computed them (ms).
  const std::vector<double>& EdgeBACovarianceTimesMs() const { return edge_ba_covariance_ms_; }
  // Per solved windowed BA window: wall time (problem build + solve on the solving thread, ms),
  // points in the problem and solver iterations.
  const std::vector<double>& WindowedBATimesMs() const { return windowed_ba_times_ms_; }
  const std::vector<double>& WindowedBAPoints() const { return windowed_ba_points_; }
  const std::vector<double>& WindowedBAIterations() const { return windowed_ba_iterations_; }
  // Photometric targets each applied window left out as outliers.
  const std::vector<double>& WindowedBAOutlierTargets() const {
    return windowed_ba_outlier_targets_;
  }
  // backend.windowed_ba: every keyframe's pose after the last applied window that held it (or as
  // tracked), oldest first; empty without the windowed BA. Complete after Finish().
  std::vector<KeyframePoseRecord> WindowedBAKeyframePoses() const;
  const OdometryConfig& config() const { return config_; }

 private:
  struct ActiveKeyframe {
    int id = -1;
    int frame_index = -1;
    double timestamp = 0.0;
    SE3 world_from_kf;
    cv::Mat image;
    LineFrame lines;
    int frames_tracked = 0;
    double min_rms = 0.0;  // smallest photometric misfit of the frames tracked against it (0: none)
  };

  // Throws std::invalid_argument when `image` is not a gray image of the camera's size.
  void CheckImage(int index, const cv::Mat& image) const;
  // ProcessFrame after the preparation; `start`: when the frame's work on this thread began.
  OdometryFrameResult ProcessPrepared(int index, double timestamp, PreparedFrame frame,
                                      const cv::Mat& depth, WallClock::time_point start);
  // One frame, in the steps below (the header's steps 2-5).
  OdometryFrameResult Process(int index, double timestamp, PreparedFrame frame,
                              const cv::Mat& depth);
  // The keyframe's lines matched into the frame and what the matches say per keyframe segment.
  struct LineAssociation {
    std::vector<LineMatch> matches;
    std::vector<MatchedLine> lines_in_cur;
  };
  // The first frame becomes the keyframe with a random (or `depth`'s) map.
  void StartFirstKeyframe(int index, double timestamp, const cv::Mat& image, LineFrame lines,
                          const cv::Mat& depth, OdometryFrameResult* result);
  // Step 2: the keyframe's lines matched into the frame, predicted by the pose prior (describing
  // what the match needs first, lines.descriptor.on_demand).
  LineAssociation MatchKeyframeLines(LineFrame* lines, const SE3& prior_cur_from_kf,
                                     OdometryFrameResult* result);
  // Step 3: the map's tracking reference with the matched current lines.
  void UpdateReference(const std::vector<MatchedLine>& lines_in_cur, OdometryTiming* timing);
  // Step 4: the line gates and coarse-to-fine tracking with alternatives and a re-track.
  TrackingResult TrackFrame(const ImagePyramid& pyramid, const cv::Mat& image, int index,
                            const SE3& prior_cur_from_kf, LineAssociation* association,
                            OdometryFrameResult* result);
  // odometry.compare_solver: the same final problem solved by the other solver.
  void CompareSolvers(const ImagePyramid& pyramid, const TrackingResult& tracking,
                      OdometryFrameResult* result);
  // Step 5, tracked: the motion model and the frame's pose and status.
  void AcceptTrackedFrame(int index, const TrackingResult& tracking, OdometryFrameResult* result);
  // Step 5, tracked: a new keyframe by the keyframe criteria, or a depth-filter update.
  void MapOrSwitchKeyframe(int index, double timestamp, const cv::Mat& image, LineFrame lines,
                           const TrackingResult& tracking, LineAssociation association,
                           OdometryFrameResult* result);
  // Step 5, lost: the extrapolated pose, and a re-initialisation after
  // odometry.reinit_after_lost lost frames.
  void HandleLostFrame(int index, double timestamp, const cv::Mat& image, LineFrame lines,
                       const SE3& world_from_prior, const SE3& prior_cur_from_kf,
                       OdometryFrameResult* result);
  // Makes the frame the keyframe with id next_keyframe_id_: initial (random map) when
  // `initialize`, otherwise propagated from the current keyframe with new_from_old.
  // previous_segment: per segment of `lines`, the current keyframe's segment it was matched to
  // (or -1), for the edge BA's line association; null when not associated (window restarts).
  void StartKeyframe(int index, double timestamp, const cv::Mat& image, LineFrame lines,
                     const SE3& world_from_cam, bool initialize, const SE3& new_from_old,
                     int min_propagated_points, OdometryTiming* timing,
                     const std::vector<int>* previous_segment, const cv::Mat& depth = cv::Mat());
  // The map of the current keyframe, waiting for it after a switch.
  void RefreshMap(OdometryTiming* timing);
  TrackingResult TrackWithAlternatives(const ImagePyramid& pyramid, const cv::Mat& image, int index,
                                       const SE3& prior_cur_from_kf,
                                       const SE3& last_good_cur_from_kf,
                                       OdometryFrameResult* frame_result);
  SE3 PredictWorldFromCam(int index) const;
  // Edge BA: adds the new keyframe to the window (previous_segment: see
  // KeyframeWindow::AddKeyframe; old_from_new: its tracked pose relative to the previous
  // keyframe) and, when the window has two keyframes or more, solves it (synchronous) or submits
  // it (parallel). A null previous_segment restarts the window with this keyframe.
  void UpdateEdgeBA(const EdgeTrace& edges, const std::vector<int>* previous_segment,
                    const SE3& old_from_new);
  // Applies the results the worker has finished.
  void PollEdgeBA();
  void ApplyEdgeBA(const EdgeBAResult& result);
  // backend.edge_ba.line_depth_feedback: a kLineDepths job with the result's optimised lines
  // that the current keyframe observes (counts a failed covariance instead).
  void SendLineDepths(const EdgeBAResult& result);
  // Windowed BA: records the published maps of `map` (the current keyframe's, and the retired
  // keyframe's final one) and, when the window is ready, solves it (synchronous) or submits it.
  void UpdateWindowedBA(const KeyframeMap& map);
  void PollWindowedBA();
  void ApplyWindowedBA(const WindowedBAResult& result);
  // A bundle adjustment moved the current keyframe to world_from_kf: the last good frame, tracked
  // against it (or it), moves rigidly with it, so the motion model (relative) stays valid.
  void MoveCurrentKeyframe(const SE3& world_from_kf);
  // The current keyframe's map goes to the BA's scale (inverse depths times idepth_scale): the
  // last good frame's translation relative to the keyframe and the motion model's follow it.
  void ScaleCurrentKeyframeMap(double idepth_scale);
  void NotifyRetired(const KeyframeMap& map);
  // A new keyframe's first published map: a fresh random map on a re-initialisation keyframe
  // loses the scale (scale_lost_).
  void NoteKeyframeMap(const KeyframeMap& map);
  OdometryFrameResult Finalize(OdometryFrameResult result);

  PinholeCamera camera_;
  OdometryConfig config_;
  OdometryObserver* observer_;
  FramePreparer preparer_;                  // ProcessFrame(image)
  std::unique_ptr<LineFrontend> frontend_;  // matching and tracing (null without lines)
  Tracker tracker_;
  std::unique_ptr<Tracker> compare_tracker_;  // odometry.compare_solver, else null
  // odometry.line_consensus_max_cost_drop > 0 with lines, else null.
  std::unique_ptr<PhotometricConsensus> consensus_;
  std::unique_ptr<MappingWorker> mapper_;
  // Edge BA (null when disabled); the adjuster only in parallel mode.
  std::unique_ptr<KeyframeWindow> edge_ba_window_;
  std::unique_ptr<EdgeBundleAdjuster> edge_ba_adjuster_;
  std::vector<double> edge_ba_times_ms_;
  std::vector<double> edge_ba_covariance_ms_;
  // Windowed BA (null when disabled); the adjuster only in parallel mode.
  std::unique_ptr<WindowedBAKeyframes> windowed_ba_keyframes_;
  std::unique_ptr<WindowedBundleAdjuster> windowed_ba_adjuster_;
  std::vector<double> windowed_ba_times_ms_;
  std::vector<double> windowed_ba_points_;
  std::vector<double> windowed_ba_outlier_targets_;
  std::vector<double> windowed_ba_iterations_;

  bool initialized_ = false;
  int next_keyframe_id_ = 0;
  ActiveKeyframe keyframe_;
  ActiveKeyframe retiring_;  // the previous keyframe until its final map is reported
  std::shared_ptr<const KeyframeMap> map_;
  TrackingReference reference_;  // map_'s points + this frame's lines
  const TrackingReference* reference_source_ = nullptr;

  // Motion model: the last good pose, its frame index and the per-frame motion prev_from_cur.
  SE3 world_from_last_good_;
  int last_good_index_ = -1;
  SE3 velocity_;
  // The last good frame's brightness relative to the keyframe's (tracking.problem.brightness
  // affine; 0 with none and after a new keyframe): the next frame's initial guess, and what its
  // mapping job undoes (MappingJob::brightness).
  AffineBrightness brightness_;
  // sigma_I of the last tracked frame's solution (0 until one), handed to the next frame's
  // tracking reference and to every windowed BA window; each uses it where its
  // weighting.intensity_noise is estimated.
  double intensity_noise_sigma_ = 0.0;
  // The line covariance scale s of the last tracked frame's solution with line rows (0 before
  // the first): the next frame's tracking reference gets it (weighting.line_noise estimated
  // uses it), and so does the mapping update (mapping.line_stereo_estimated_line_noise).
  double line_noise_scale_ = 0.0;
  RetryTrigger retry_trigger_;
  int consecutive_lost_ = 0;
  bool recovering_ = false;   // a frame was lost since the last tracked one
  bool last_tracked_ = true;  // the previous frame was tracked (lost-event counting)
  int last_index_ = -1;
  // Scale segments: the first keyframe's id, the newest keyframe whose map was looked at, and
  // whether a fresh random map replaced the scale since the last tracked frame.
  int first_keyframe_id_ = -1;
  int last_noted_keyframe_id_ = -1;
  bool scale_lost_ = false;
  OdometryStatistics stats_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_ODOMETRY_H_
