// Per-frame outputs of the odometry without any I/O in the core (DSO's Output3DWrapper idea): the
// odometry calls an observer; experiments/ plugs in writers (trajectory, images, PLY).
// Every call happens on the thread that calls Odometry::ProcessFrame / Finish, in frame order.
#ifndef PLDVO_BACKEND_ODOMETRY_ODOMETRY_OBSERVER_H_
#define PLDVO_BACKEND_ODOMETRY_ODOMETRY_OBSERVER_H_

#include <opencv2/core.hpp>
#include <string>

#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/tracking/tracker.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// What happened to a frame.
enum class FrameStatus {
  kKeyframe,       // tracked (or the first frame) and made the new keyframe
  kTracked,        // tracked against the keyframe
  kRecovered,      // tracked again after lost frames
  kLost,           // not tracked: pose extrapolated from the last good pose, not mapped
  kReinitialized,  // lost, and made a keyframe at the extrapolated pose (recovery)
  kFailed,         // the frame could not be loaded or processed (pose extrapolated)
};
const char* FrameStatusName(FrameStatus status);
// Tracked, keyframe or recovered: the pose is an estimate, not an extrapolation.
inline bool IsTracked(FrameStatus status) {
  return status == FrameStatus::kKeyframe || status == FrameStatus::kTracked ||
         status == FrameStatus::kRecovered;
}

// Wall-clock milliseconds of one frame (the components of the paper's Table III).
struct OdometryTiming {
  double pyramid_ms = 0.0;      // image pyramid with gradients
  double detection_ms = 0.0;    // line detection and merging
  double description_ms = 0.0;  // LBD
  double matching_ms = 0.0;     // keyframe -> frame line matching
  double tracing_ms = 0.0;      // edge tracing of a new keyframe's lines
  double wait_ms = 0.0;         // waiting for a new keyframe's map (parallel mapping)
  double reference_ms = 0.0;    // matched lines into the tracking reference, overlap
  double tracking_ms = 0.0;     // coarse-to-fine tracking incl. alternative guesses
  double consensus_ms = 0.0;    // of tracking_ms: the photometric consensus check's solve
  // Parallel mapping: mapping work finished on the mapping thread since the previous frame;
  // inline mapping: this frame's mapping job.
  double mapping_ms = 0.0;
  // Everything ProcessFrame does on the calling thread (with inline mapping this includes the
  // mapping job).
  double tracking_thread_ms = 0.0;
  // The comparison solve (odometry.compare_solver); not included in tracking_thread_ms.
  double compare_tracking_ms = 0.0;
};

struct OdometryFrameResult {
  int index = 0;           // dataset frame index
  double timestamp = 0.0;  // dataset timestamp, seconds
  FrameStatus status = FrameStatus::kLost;
  SE3 world_from_cam;       // the estimate (tracked) or the extrapolation (lost, failed)
  int keyframe_id = -1;     // the keyframe the frame was tracked against / became
  TrackingResult tracking;  // the chosen tracking result (empty levels when not tracked)
  int alternatives_tried = 0;
  // Alternatives that would have won but motion_gated_inlier_rows kept out.
  int alternatives_gated = 0;
  int num_lines = 0;    // line segments of the frame
  int num_matches = 0;  // matched to the keyframe
  // odometry.line_consensus_max_cost_drop: the line term disagreed with the photometric one and
  // the frame keeps the photometric-only pose.
  bool line_term_dropped = false;
  // odometry.random_map_warmup_updates: the keyframe map had fused fewer stereo updates since its
  // random initialisation, and the frame was tracked without the point-to-line term (its matches
  // still feed the mapping).
  bool line_term_withheld = false;
  int num_line_outliers = 0;  // matches unmatched by the verification (prior gate + after tracking)
  int num_reference_points = 0;  // level-0 points of the keyframe map
  double mean_idepth = 0.0;      // of the keyframe map
  OdometryTiming timing;
  std::string message;  // why a frame is lost / failed
  // odometry.compare_solver: the same final tracking problem solved by the other solver, and the
  // wall time of the run's final solve (TrackingResult::ms of `tracking`) vs the other's.
  bool compared = false;
  TrackingStatus compared_status = TrackingStatus::kLost;
  SE3 world_from_cam_compared;  // its pose, with this run's keyframe pose
  // Its finest level's initial and final cost and valid rows (the run's:
  // tracking.levels.back().initial_cost / final_cost, tracking.valid_residuals): which solver
  // stopped lower where the poses differ. Each solver starts a level where it left the coarser
  // one, so the finest level's starts differ a little too.
  double compared_initial_cost = 0.0;
  double compared_final_cost = 0.0;
  int compared_valid_residuals = 0;
};

// A keyframe whose map is final (replaced by a new keyframe, or the last one at Finish).
struct KeyframeInfo {
  int keyframe_id = -1;
  int frame_index = -1;
  double timestamp = 0.0;
  SE3 world_from_kf;
  cv::Mat image;  // CV_32F
  PinholeCamera camera;
};

class OdometryObserver {
 public:
  virtual ~OdometryObserver() = default;
  // After every frame, tracked or not.
  virtual void OnFrame(const OdometryFrameResult& /*result*/) {}
  // Whether the tracking iterations of this frame are wanted (they cost a reprojection of every
  // edge point per iteration).
  virtual bool WantsTrackingIterations(int /*frame_index*/) const { return false; }
  // Every tracking iteration of a wanted frame, with the frame's image (CV_32F).
  virtual void OnTrackingIteration(int /*frame_index*/, const cv::Mat& /*image*/,
                                   const TrackingIteration& /*iteration*/) {}
  // Whether keyframe maps are wanted (they cost one regularisation per keyframe).
  virtual bool WantsKeyframeMaps() const { return false; }
  virtual void OnKeyframeFinished(const KeyframeInfo& /*keyframe*/,
                                  const SemiDenseDepthMap& /*map*/) {}
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_ODOMETRY_OBSERVER_H_
