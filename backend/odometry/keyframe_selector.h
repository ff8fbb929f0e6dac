// When a tracked frame becomes the new keyframe (KeyframeOptions in odometry_config.h): the
// scene-relative distance |t_cur_from_kf| * mean_idepth (the baseline in units of the mean scene
// depth, independent of the arbitrary monocular scale; Engel et al. ICCV 2013 Sec. 3, LSD-SLAM's
// keyframe distance), the overlap (fraction of the keyframe's points reprojecting inside the
// frame), the tracked frame's inlier fraction, the growth of its photometric misfit since the
// keyframe (DSO's residual criterion, Engel et al. PAMI 2018 Sec. 3.1) and a frame count.
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
  std::string reason;  // "distance", "overlap", "inliers", "rms", "max_frames" or empty
};

// What a tracked frame says about its keyframe.
struct KeyframeEvidence {
  SE3 cur_from_kf;
  double mean_idepth = 0.0;      // of the keyframe's map
  double overlap = 1.0;          // fraction of the keyframe's points inside the frame
  double inlier_fraction = 1.0;  // TrackingResult::inlier_fraction
  // The frame's photometric misfit over the smallest of the frames tracked against the keyframe
  // (this one included), >= 1. The misfit is the image noise (gray levels) the frame's
  // photometric errors imply (TrackingResult::intensity_noise_sigma), else their RMS.
  double rms_growth = 1.0;
  int frames_tracked = 0;  // frames tracked against the keyframe, this one included
};

KeyframeDecision DecideKeyframe(const KeyframeOptions& options, const KeyframeEvidence& evidence);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_KEYFRAME_SELECTOR_H_
