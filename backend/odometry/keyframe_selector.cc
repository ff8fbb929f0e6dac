#include "backend/odometry/keyframe_selector.h"

namespace pldvo {

KeyframeDecision DecideKeyframe(const KeyframeOptions& options, const SE3& cur_from_kf,
                                double mean_idepth, double overlap, double inlier_fraction,
                                int frames_tracked) {
  KeyframeDecision decision;
  decision.relative_distance = cur_from_kf.translation().norm() * mean_idepth;
  decision.overlap = overlap;
  if (frames_tracked < options.min_frames) return decision;
  if (decision.relative_distance > options.max_relative_distance) {
    decision.reason = "distance";
  } else if (overlap < options.min_overlap) {
    decision.reason = "overlap";
  } else if (inlier_fraction < options.min_inlier_fraction) {
    decision.reason = "inliers";
  } else if (options.max_frames > 0 && frames_tracked >= options.max_frames) {
    decision.reason = "max_frames";
  }
  decision.new_keyframe = !decision.reason.empty();
  return decision;
}

}  // namespace pldvo
