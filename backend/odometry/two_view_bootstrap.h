// Two-view bootstrap of the first keyframe's map (odometry.two_view_bootstrap; docs/odometry.md,
// "Two-view bootstrap").
//
// The semi-dense VO starts from a random inverse-depth map (Engel 2013 Sec. 2.1) and tracks the
// first frames against it. Under rotation-dominant motion that yields a self-consistent but wrong
// pair of poses and map (docs/odometry.md, "Keyframe maps in monocular runs"). Here the first
// frames' motion comes from image geometry instead, as in feature-based monocular SLAM
// (ORB-SLAM, SVO):
//   1. corners of frame 0 (Shi-Tomasi, down to corner_quality of the strongest) are tracked
//      frame to frame by pyramidal Lucas-Kanade with a forward-backward check;
//   2. at every frame k, the essential matrix between frame 0 and k (five-point RANSAC) and its
//      decomposition give (R, t) and triangulated corners; k passes the parallax gates when at
//      least min_inliers corners are triangulated in front of both cameras with a median
//      parallax angle of at least min_parallax_deg, and the corners moved by at least
//      min_rotation_free_parallax_px (median) more than the best-fitting rotation explains: with
//      less, the essential matrix fits the tracking noise and its decomposition can be any
//      motion, while the triangulated parallax of that motion still looks large;
//   3. such a frame is tested by a bundle adjustment of up to 200 of the corners over up to 8
//      frames 0..k (Ceres, Huber loss; frame 0 fixed, |t_k| fixed): k is the second view when
//      the adjusted translation direction's standard deviation (covariance for 1 px noise) is
//      at most max_direction_std_deg and the adjusted directions of the last stable_frames
//      consecutive tested frames agree to within it. Weak corners and forward motion leave the
//      direction uncertain; a wrong decomposition or local minimum jumps from frame to frame;
//   4. the poses of frames 1..k and all inlier corners are adjusted over every frame 0..k,
//      starting from poses interpolated between frame 0 and the two-view pose;
//   5. with the scale set by a median corner inverse depth of 1, frame 0's semi-dense map is
//      estimated from that median (two_view_map_prior; the map does not depend on the seed) by
//      the mapping's own stereo and EKF with the poses of frames 1..k (photometric stereo, no
//      lines: configurations with the same gates start alike);
//      then, for each of two_view_photometric_passes, up to 8 evenly spaced frames 0..k and
//      2000 of the map's points are adjusted photometrically (the windowed BA's eq. 2 rows,
//      frame 0 hosting; DSO's initialiser adjusts poses and depths jointly in the same way),
//      the frames between take the interpolated correction, and the map is estimated again.
//      Corners drift by a pixel or two over tens of frames; the image's edges do not.
// The run then starts from that map (its observed hypotheses) with inverse-depth variance
// odometry.bootstrap_idepth_var, and tracks frames 1..k again.
#ifndef PLDVO_BACKEND_ODOMETRY_TWO_VIEW_BOOTSTRAP_H_
#define PLDVO_BACKEND_ODOMETRY_TWO_VIEW_BOOTSTRAP_H_

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/odometry/corner_epipolar_error.h"
#include "backend/odometry/odometry_config.h"
#include "core/dataset.h"
#include "core/se3.h"

namespace pldvo {

struct TwoViewBootstrap {
  // Frame 0's z-depth (CV_32F; 0 where the map has no observed hypothesis), median inverse depth
  // 1: the start of the run proper.
  cv::Mat depth;
  int second_view = -1;       // frame index k of the second view
  SE3 second_from_first;      // its pose (cam_from_ref), in the scale of `depth`
  int tracks = 0;             // corners tracked from frame 0 to k
  int inliers = 0;            // of which: essential-matrix inliers triangulated in front
  double parallax_deg = 0.0;  // their median parallax angle
  double rotation_free_parallax_px = 0.0;  // their median parallax no rotation explains
  double direction_std_deg = 0.0;  // the adjusted translation direction's uncertainty (1 px noise)
  int photometric_points = 0;      // adjusted in the last photometric pass (0: none)
  int points = 0;                  // observed hypotheses of frame 0's map
  double ms = 0.0;                 // wall time
};

// Why a two-view start failed; tracks_lost_at is the frame where fewer than two_view_min_inliers
// corners were left (0: frame 0 has fewer; -1 when the start failed otherwise): a later anchor
// may start there. first_gated: the first frame that passed the parallax gates (-1: none), where
// a later anchor may start when the direction gate failed.
class TwoViewBootstrapFailure : public std::runtime_error {
 public:
  TwoViewBootstrapFailure(const std::string& what, int tracks_lost_at, int first_gated = -1)
      : std::runtime_error(what), tracks_lost_at(tracks_lost_at), first_gated(first_gated) {}
  int tracks_lost_at;
  int first_gated;
};

// Where a re-anchored start begins after `failure`, relative to the failed start's anchor: where
// the corners were lost (the next frame if that is the anchor itself), or with
// after_direction_gate, where the direction gate failed with the corners kept, the first frame
// that passed the parallax gates; -1: nowhere (no parallax, no frames).
int TwoViewRestartFrame(const TwoViewBootstrapFailure& failure, bool after_direction_gate);

// The parallax of the matched pixels x0[i] <-> xk[i] that no rotation explains, px: the median
// angle between the rays of xk and the rays of x0 turned by the rotation that best aligns them
// (Kabsch on unit rays), times the focal length sqrt(fx fy). Pure rotation gives 0 whatever the
// essential matrix's decomposition says, and composing any rotation with the motion leaves it
// unchanged; a translation t gives about |t| sin(angle to t) / depth per ray, minus what the best
// rotation absorbs, so it bounds the translation's signal from below. Compared with the tracking
// noise, it says whether an essential matrix fits the motion or the noise. 0 for fewer than 3
// pairs; std::invalid_argument when the sizes differ.
double RotationFreeParallaxPx(const std::vector<cv::Point2f>& x0,
                              const std::vector<cv::Point2f>& xk, const cv::Matx33d& K);

// Runs the two-view bootstrap over the first min(num_frames, two_view_max_frames) frames of
// `dataset` with config.mapping. Throws TwoViewBootstrapFailure, saying why, when frame 0 cannot be
// loaded or has too few corners, when the tracks are lost, when no frame reaches the parallax,
// when no frame passes the direction gate (then, and when the tracks are lost after a frame
// passed the parallax gates after odometry.random_start_frames, *unsettled_tracks, if given,
// gets every corner's track, lost ones included: they fix the direction roughly,
// corner_epipolar_error.h; with odometry.random_start_reanchored_corners, tracks lost before
// that horizon go too, with corners detected again where they were lost, up to the horizon), or
// when the map ends without observed hypotheses.
TwoViewBootstrap BootstrapFromTwoViews(const Dataset& dataset, const OdometryConfig& config,
                                       int num_frames, CornerTracks* unsettled_tracks = nullptr);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_TWO_VIEW_BOOTSTRAP_H_
