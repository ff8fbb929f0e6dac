// When a tracked frame becomes the new keyframe (KeyframeOptions in odometry_config.h): the
// scene-relative distance |t_cur_from_kf| * mean_idepth (the baseline in units of the mean scene
// depth, independent of the arbitrary monocular scale; Engel et al. ICCV 2013 Sec. 3, LSD-SLAM's
// keyframe distance), the overlap (fraction of the keyframe's points reprojecting inside the
// frame), the tracked frame's inlier fraction and a frame count.
#ifndef PLDVO_BACKEND_ODOMETRY_KEYFRAME_SELECTOR_H_
#define PLDVO_BACKEND_ODOMETRY_KEYFRAME_SELECTOR_H_

#include <string>

#include "backend/odometry/odometry_config.h"
#include "core/se3.h"

namespace pldvo {

struct KeyframeDecision {
  bool new_keyframe = false;
  double relative_distance = 0.0;  // |t_cur_from_kf| * mean_idepth
  double overlap = 1.0;
  std::string reason;  // "distance", "overlap", "inliers", "max_frames" or empty
};

// frames_tracked: frames tracked against the keyframe, this one included; inlier_fraction:
// the frame's TrackingResult::inlier_fraction.
KeyframeDecision DecideKeyframe(const KeyframeOptions& options, const SE3& cur_from_kf,
                                double mean_idepth, double overlap, double inlier_fraction,
                                int frames_tracked);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_KEYFRAME_SELECTOR_H_
