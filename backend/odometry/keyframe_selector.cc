#include "backend/odometry/keyframe_selector.h"

namespace pldvo {

KeyframeDecision DecideKeyframe(const KeyframeOptions& options, const KeyframeEvidence& evidence) {
  KeyframeDecision decision;
  decision.relative_distance = evidence.cur_from_kf.translation().norm() * evidence.mean_idepth;
  decision.overlap = evidence.overlap;
  if (evidence.frames_tracked < options.min_frames) return decision;
  if (decision.relative_distance > options.max_relative_distance) {
    decision.reason = "distance";
  } else if (evidence.overlap < options.min_overlap) {
    decision.reason = "overlap";
  } else if (evidence.inlier_fraction < options.min_inlier_fraction) {
    decision.reason = "inliers";
  } else if (options.max_rms_growth > 0.0 && evidence.rms_growth > options.max_rms_growth) {
    decision.reason = "rms";
  } else if (options.max_frames > 0 && evidence.frames_tracked >= options.max_frames) {
    decision.reason = "max_frames";
  }
  decision.new_keyframe = !decision.reason.empty();
  return decision;
}

}  // namespace pldvo
