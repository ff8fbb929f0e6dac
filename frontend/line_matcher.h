// Keyframe -> current frame line matching (seed paper Sec. VI-A(1)). The current frame's
// segments are indexed in a bucket grid (every coarse cell a segment passes through x directed
// orientation bin). Each reference segment, mapped into the current frame by an optional
// predictor (identity without one), collects the candidates in the buckets around it that
//   - point the same way within max_angle_deg (predicted_max_angle_deg with a prediction),
//   - have their midpoint within the radius of its line and overlap its extent grown by the
//     radius along it (search_radius_px, or predicted_radius_px with a prediction).
// Among the candidates the smallest LBD Hamming distance wins if it is at most max_hamming,
// passes the ratio test best < ratio * second best, and (with `mutual`) the current segment
// has no reference segment at a smaller distance among the references that gated it.
#ifndef PLDVO_FRONTEND_LINE_MATCHER_H_
#define PLDVO_FRONTEND_LINE_MATCHER_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "frontend/line_frontend_options.h"
#include "frontend/line_segment.h"

namespace pldvo {

struct LineMatch {
  int ref_index = -1;  // into the reference (keyframe) segments
  int cur_index = -1;  // into the current frame's segments
  int distance = 0;    // Hamming distance of the LBD descriptors (of 256 bits)
};

// Predicts where a reference segment appears in the current frame (endpoints in current-frame
// pixels, same direction); returns false when it cannot (e.g. behind the camera), and that
// reference segment is then not matched.
using SegmentPredictor = std::function<bool(
    const LineSegment& segment_in_ref, Eigen::Vector2d* start_in_cur, Eigen::Vector2d* end_in_cur)>;

// A predictor from a 3x3 homography mapping reference pixels to current pixels (e.g. the
// infinite homography K R K^-1 of a predicted rotation, or a pure offset).
SegmentPredictor PredictorFromHomography(const Eigen::Matrix3d& cur_from_ref);

class LineMatcher {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit LineMatcher(const LineMatcherOptions& options);

  // Matches, in the order of the reference segments: Gate, then Select. Descriptors are N x 32
  // CV_8U rows aligned with their segments. `predictor` may be empty.
  std::vector<LineMatch> Match(const std::vector<LineSegment>& ref_segments,
                               const cv::Mat& ref_descriptors,
                               const std::vector<LineSegment>& cur_segments,
                               const cv::Mat& cur_descriptors,
                               const SegmentPredictor& predictor = nullptr) const;

  // The geometric test: per reference segment, the current segments within its direction and
  // radius gates (no descriptor is read).
  std::vector<std::vector<int>> Gate(const std::vector<LineSegment>& ref_segments,
                                     const std::vector<LineSegment>& cur_segments,
                                     const SegmentPredictor& predictor = nullptr) const;

  // The descriptor test on Gate's candidates: smallest Hamming distance, max_hamming, ratio
  // and mutual checks. Reads only the rows of gated pairs.
  std::vector<LineMatch> Select(const std::vector<std::vector<int>>& gated,
                                const cv::Mat& ref_descriptors, const cv::Mat& cur_descriptors,
                                size_t num_cur_segments) const;

 private:
  LineMatcherOptions options_;
};

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_MATCHER_H_
