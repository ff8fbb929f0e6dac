// How well a monocular start's motion fits frame 0's tracked corners (docs/bootstrap.md, "Best of
// several random starts").
//
// A start from the random map settles into one of several self-consistent pairs of map and
// motion; on the texture-less rooms the wrong ones move 20-25 deg off the true direction and fit
// the images about as well as the right one. Corners take no part in that start, so where they
// fix the translation direction (the two-view bootstrap reached its direction gate) they tell the
// starts apart: the epipolar geometry of the right motion fits them, a wrong direction does not.
#ifndef PLDVO_BACKEND_ODOMETRY_CORNER_EPIPOLAR_ERROR_H_
#define PLDVO_BACKEND_ODOMETRY_CORNER_EPIPOLAR_ERROR_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// Corners followed frame to frame: per corner its pixel positions in frames a, a + 1, ... up to
// the last frame it was tracked to, a its anchor (the frame it was detected in). Frame 0's corners
// have anchor 0; where they were lost early, corners detected later take over (re-anchored).
struct CornerTracks {
  std::vector<std::vector<cv::Point2f>> positions;
  std::vector<int> anchors;  // per track; empty: every track from frame 0
  int Anchor(size_t track) const { return anchors.empty() ? 0 : anchors[track]; }
};

// Frames with fewer corners tracked to them do not count.
constexpr int kMinEpipolarCorners = 20;

// Per anchor a and frame k > a with at least kMinEpipolarCorners of a's corners tracked to it, the
// corners that one motion explains: the five-point RANSAC consensus of a -> k at 1 px (a
// texture-less room's weak corners drift, and by frame 40 about half of them fit no motion), on the
// normalised plane. It does not depend on a candidate's motion, so the random start finds it once
// for all of them.
struct CornerConsensus {
  struct Frame {
    int anchor = 0, k = 0;
    std::vector<Eigen::Vector2d> in_0, in_k;  // corner i seen at in_0[i] (anchor) and in_k[i]
  };
  std::vector<Frame> frames;
  double focal_px = 0.0;  // sqrt(fx fy): normalised-plane distances to pixels
};

// The consensus of frames 1 .. num_frames - 1 (all of an anchor's tracks, when RANSAC finds none).
CornerConsensus FindCornerConsensus(const CornerTracks& tracks, const PinholeCamera& camera,
                                    int num_frames);

// For every consensus frame k with a pose (world_from_cam[k], frame 0 first) that moved from its
// anchor a, the median Sampson distance of its corners to the epipolar geometry E = [t]x R of
// cam_k <- cam_a (t of unit length: the distance does not depend on the scale), in pixels; returns
// the mean over those frames, and NaN when no frame counts.
double CornerEpipolarErrorPx(const CornerConsensus& consensus,
                             const std::vector<SE3>& world_from_cam);

// Both in one: the consensus of frames 1 .. world_from_cam.size() - 1, and its error.
double CornerEpipolarErrorPx(const CornerTracks& tracks, const std::vector<SE3>& world_from_cam,
                             const PinholeCamera& camera);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_CORNER_EPIPOLAR_ERROR_H_
