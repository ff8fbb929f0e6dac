// The mapping side of the odometry: a DepthMapper (semi-dense keyframe depth filter) fed with
// jobs (initialise a keyframe, fuse a tracked frame, switch to a new keyframe, fuse the edge BA's
// optimised lines, DepthMapper::FuseLineDepths, shift depths by the windowed BA's corrections,
// DepthMapper::ApplyIdepthCorrections), run either in its own thread (parallel) or
// inline on the caller's thread (deterministic). After every job the worker publishes an
// immutable KeyframeMap: the regularised map and the tracking reference points built from it
// (reference_builder.h), which the tracking thread picks up without copying the filter state.
//
// Ordering: jobs run in submission order. The map a frame is tracked against (MapForTracking)
// holds every job submitted so far but the newest `lag` frame updates after the last other job,
// whichever thread ran them: inline, the updates are held back that long; in parallel with
// wait_when_behind, the tracking waits for that state and gets it even when the thread is ahead,
// so a parallel run is the inline run. Without wait_when_behind (real time), the tracking gets
// the latest map, and when more than `max_pending_updates` frame updates wait the oldest is
// dropped (counted in dropped_updates()); keyframe and line-depth / depth-correction jobs are
// never dropped.
#ifndef PLDVO_BACKEND_ODOMETRY_MAPPING_WORKER_H_
#define PLDVO_BACKEND_ODOMETRY_MAPPING_WORKER_H_

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/mapping_options.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/tracking/tracking_reference.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "frontend/edge_tracer.h"
#include "residuals/affine_brightness.h"

namespace pldvo {

// One published state of the current keyframe's map.
struct KeyframeMap {
  int keyframe_id = -1;
  int num_updates = 0;  // frames fused into this keyframe so far
  // RegularizedMap(options.regularize, options.line_regularization) of the filter state.
  std::shared_ptr<const SemiDenseDepthMap> map;
  // Points of every level (lines_in_cur empty), from `map`.
  std::shared_ptr<const TrackingReference> reference;
  double mean_idepth = 0.0;  // of `map`
  int num_points = 0;        // level-0 reference points
  // On a keyframe switch with keep_retired_map: the previous keyframe's final regularised map.
  std::shared_ptr<const SemiDenseDepthMap> retired_map;
  int retired_keyframe_id = -1;
  PropagationStats propagation;  // of the switch that created this keyframe
  bool random_init = false;      // the map was (re)initialised at random
  // Stereo updates fused since the map's last random (re)initialisation, across the keyframe
  // switches that propagated it; -1 when it descends from a measured start (depth image).
  int updates_since_random_init = -1;
};

struct MappingJob {
  enum class Kind { kInitialize, kUpdate, kNewKeyframe, kLineDepths, kIdepthCorrections };
  Kind kind = Kind::kUpdate;
  int keyframe_id = -1;  // the keyframe the job concerns (the new one for kNewKeyframe)
  int frame_index = -1;
  cv::Mat image;  // CV_32F or CV_8U, the camera's size
  // The image's brightness relative to the current keyframe's (residuals/affine_brightness.h):
  // kUpdate stereo compares the keyframe with e^-a (I - b); kNewKeyframe propagation compares
  // the old keyframe's intensities with the new one's taken to the old brightness. Every
  // keyframe keeps its own image.
  AffineBrightness brightness;
  // kUpdate: cur_from_kf of the tracked frame and its lines matched to the keyframe edges.
  SE3 cur_from_kf;
  std::vector<MatchedLine> lines_in_cur;
  // kUpdate: the tracked pose's covariance (tracking.pose_covariance; zero when not computed).
  Matrix6d pose_covariance = Matrix6d::Zero();
  // kUpdate: s^2 of the current lines' covariance in the line-guided stereo (1: as fitted;
  // mapping.line_stereo_estimated_line_noise).
  double line_cov_scale = 1.0;
  // kInitialize / kNewKeyframe: the new keyframe's traced edges and pyramid levels.
  EdgeTrace edges;
  int num_levels = 1;
  // kInitialize: a z-depth image (CV_32F metres, 0 = none) to initialise from, with this
  // inverse-depth variance; empty: options.init (random / constant).
  cv::Mat depth;
  double depth_idepth_var = 0.0;
  // kNewKeyframe: new_from_old, and the hypotheses needed to keep the propagated map (fewer:
  // random re-initialisation; 0 always keeps it).
  SE3 new_from_old;
  int min_propagated_points = 0;
  bool keep_retired_map = false;
  // kLineDepths: the edge BA's optimised lines observed by keyframe_id, in its camera frame
  // (DepthMapper::FuseLineDepths); ignored when keyframe_id is no longer current.
  std::vector<KeyframeLine> line_depths;
  // kIdepthCorrections: the windowed BA's inverse-depth corrections of keyframe_id's hypotheses
  // and, with move_keyframe, new_from_old is the keyframe's frame moved relative to the keyframe
  // it was propagated from, and the other hypotheses are scaled by idepth_scale
  // (DepthMapper::ApplyIdepthCorrections); ignored when keyframe_id is no longer current.
  std::vector<IdepthCorrection> idepth_corrections;
  bool move_keyframe = false;
  double idepth_scale = 1.0;
};

class MappingWorker {
 public:
  // Throws std::invalid_argument on invalid camera or options.
  // With wait_when_behind no update is dropped: the map sees every frame whatever the machine's
  // load. Inline (not parallel), an update runs once `lag` later updates were submitted, or
  // before the next keyframe or line-depth job, or at Flush.
  MappingWorker(const PinholeCamera& camera, const MappingOptions& options, bool parallel,
                int max_pending_updates, bool wait_when_behind = false, int lag = 0);
  ~MappingWorker();
  MappingWorker(const MappingWorker&) = delete;
  MappingWorker& operator=(const MappingWorker&) = delete;

  // Runs the job inline (not parallel; updates may be held back, see the constructor) or queues
  // it; never blocks. A job that throws is counted in failed_jobs() and leaves the map as it was.
  void Submit(MappingJob job);
  // The map the next frame is tracked against (see Ordering above); blocks until the mapping
  // thread has run the jobs it needs. Real time: the latest, once keyframe_id's is published.
  std::shared_ptr<const KeyframeMap> MapForTracking(int keyframe_id);
  // The latest published map (nullptr before the first keyframe).
  std::shared_ptr<const KeyframeMap> Latest() const;
  // Blocks until every submitted job has run.
  void Flush();

  // Wall time in ms of every job run so far, and of those finished since the last call.
  std::vector<double> JobTimesMs() const;
  double TakeRecentJobMs();
  int dropped_updates() const;
  int failed_jobs() const;
  // Sum of LineDepthFusionStats::fused / ::outliers over every kLineDepths job.
  int line_depths_fused() const;
  int line_depth_outliers() const;
  // Sum of DepthMapper::ApplyIdepthCorrections over every kIdepthCorrections job.
  int idepth_corrections_applied() const;
  // The stereo's counts (FrameUpdateStats: searches, line-guided matches, fusions, outliers,
  // removed and filled hypotheses) summed over every kUpdate job.
  FrameUpdateStats stereo_counts() const;

 private:
  void Run(const MappingJob& job);
  // Blocks until the published map belongs to keyframe_id (or the worker failed it); returns
  // the latest map.
  std::shared_ptr<const KeyframeMap> WaitForKeyframe(int keyframe_id);
  // The job's keyframe with the random initial map (options.init); restarts the update count.
  void InitializeRandomMap(const MappingJob& job, KeyframeMap* published);
  void RunOldestHeldBack();
  // Parallel with wait_when_behind: the job after which MapForTracking's map was published.
  int64_t RequiredSeq() const;
  void TrimHistory();
  void Publish(std::shared_ptr<KeyframeMap> keyframe_map);
  void ThreadLoop();

  PinholeCamera camera_;
  MappingOptions options_;
  bool parallel_;
  int max_pending_updates_;
  bool wait_when_behind_;
  int lag_;
  std::deque<MappingJob> held_back_;  // inline: updates waiting for lag_ later ones
  DepthMapper mapper_;                // touched only by the job runner
  // RegularizedMap of mapper_'s state when the last job published it (null when a job changed the
  // state since): the next keyframe switch propagates it. Touched only by the job runner.
  std::shared_ptr<const SemiDenseDepthMap> state_map_;
  ImagePyramid keyframe_levels_;  // the keyframe's pyramid for the reference intensities
  int keyframe_id_ = -1;
  int num_updates_ = 0;
  int updates_since_random_init_ = -1;  // KeyframeMap::updates_since_random_init

  mutable std::mutex mutex_;
  std::condition_variable job_ready_;
  std::condition_variable job_done_;
  struct QueuedJob {
    int64_t seq = 0;  // 1, 2, ... in submission order
    MappingJob job;
  };
  std::deque<QueuedJob> queue_;
  int64_t submitted_seq_ = 0;
  int64_t barrier_seq_ = 0;  // the newest job that is not a frame update
  int64_t done_seq_ = 0;
  // Parallel with wait_when_behind: the map published after each job, from the oldest that
  // MapForTracking may still return.
  std::deque<std::pair<int64_t, std::shared_ptr<const KeyframeMap>>> history_;
  bool busy_ = false;
  bool stop_ = false;
  std::shared_ptr<const KeyframeMap> latest_;
  std::vector<double> job_ms_;
  double recent_job_ms_ = 0.0;
  int dropped_updates_ = 0;
  int failed_jobs_ = 0;
  int line_depths_fused_ = 0;
  int line_depth_outliers_ = 0;
  int idepth_corrections_applied_ = 0;
  FrameUpdateStats stereo_counts_;
  int failed_keyframe_id_ = -1;
  std::thread thread_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_MAPPING_WORKER_H_
