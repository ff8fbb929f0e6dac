// Ground truth for one line match from a depth image and the true relative pose: is the current
// segment the keyframe segment's image in the current frame? Unlike a judgement by the scene's
// modelled 3D edges (tests/frontend/line_ground_truth.h), it also judges matches between texture
// lines, which lie on no modelled edge.
//
// The keyframe segment is sampled every `sample_step_px`; each sample is lifted with the smallest
// depth in a (2 window_radius_px + 1)^2 window around it (the occluding side of a depth edge,
// where an edge's 3D points lie), moved by cur_from_ref and projected. The match is correct when
// at least min_agreeing_fraction of the projected samples lie within max_distance_px of the
// current segment's infinite line (what the point-to-line residual and the line-guided stereo
// use; collinear pieces of one 3D line count as the same line, and a line turned by a few degrees
// fails at its ends). Unverifiable when fewer than min_projected_fraction of the samples
// (or fewer than 3) have a depth and project in front of the current camera, inside its image.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_LINE_MATCH_GROUND_TRUTH_H_
#define PLDVO_EXPERIMENTS_EVALUATION_LINE_MATCH_GROUND_TRUTH_H_

#include <opencv2/core.hpp>

#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "frontend/line_matcher.h"
#include "frontend/line_segment.h"

namespace pldvo {

enum class LineMatchTruth { kCorrect, kWrong, kUnverifiable };

struct LineMatchTruthOptions {
  double sample_step_px = 2.0;
  int window_radius_px = 2;
  double max_distance_px = 2.0;
  double min_agreeing_fraction = 0.8;
  double min_projected_fraction = 0.5;
};

// A keyframe pixel in the current frame: lifted with the smallest depth in the window of
// window_radius_px around it, moved by cur_from_ref and projected to *pixel_in_cur. False without
// a depth there or when the point lies less than 5 cm in front of the current camera.
// ref_depth: the keyframe's z-depth (CV_32F, metres, <= 0 where unknown); throws
// std::invalid_argument unless it is CV_32F of the camera's size.
bool TransferPixelByDepth(const PinholeCamera& camera, const cv::Mat& ref_depth,
                          const SE3& cur_from_ref, const Eigen::Vector2d& pixel_in_ref,
                          int window_radius_px, Eigen::Vector2d* pixel_in_cur);

// The matcher's prediction from the true pose: both endpoints moved by TransferPixelByDepth.
SegmentPredictor PredictorFromDepth(const PinholeCamera& camera, const cv::Mat& ref_depth,
                                    const SE3& cur_from_ref, int window_radius_px = 2);

LineMatchTruth JudgeLineMatchByDepth(const PinholeCamera& camera, const LineSegment& ref,
                                     const cv::Mat& ref_depth, const SE3& cur_from_ref,
                                     const LineSegment& cur,
                                     const LineMatchTruthOptions& options = {});

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_LINE_MATCH_GROUND_TRUTH_H_
