// Edge tracing of keyframe lines (seed paper Sec. VI-A(1)): every selected keyframe segment is
// rasterised into the pixels it passes through (one pixel per step along its major axis, the
// pixel nearest the line) and widened by half_width_px pixels on each side across the line
// (along the minor axis). A pixel claimed by several lines goes to the line nearest to its
// centre (ties: the lower id). Every traced pixel lies within half_width_px + 0.5 pixels of
// its segment (the rounding error plus the widening, measured along the minor axis, which is
// at least the perpendicular distance).
// The result is an edge-id map (CV_32S, the segment's index or -1) and, per traced line, its
// segment (with l and Sigma_l) and its pixels; map and lists agree exactly.
#ifndef PLDVO_FRONTEND_EDGE_TRACER_H_
#define PLDVO_FRONTEND_EDGE_TRACER_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "frontend/line_frontend_options.h"
#include "frontend/line_segment.h"

namespace pldvo {

struct TracedLine {
  int id = -1;          // index of the segment in the keyframe's list = its value in id_map
  LineSegment segment;  // endpoints, l and Sigma_l
  std::vector<Eigen::Vector2i> pixels;  // (x, y)
};

struct EdgeTrace {
  cv::Mat id_map;                 // CV_32S, image size; line id or -1
  std::vector<TracedLine> lines;  // in the order of the ids given to Trace
};

class EdgeTracer {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit EdgeTracer(const EdgeTracerOptions& options);

  // Traces segments[id] for every id in `ids` (each at most once, in range) into an image of
  // `image_size`.
  EdgeTrace Trace(const std::vector<LineSegment>& segments, const std::vector<int>& ids,
                  const cv::Size& image_size) const;

 private:
  EdgeTracerOptions options_;
};

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_EDGE_TRACER_H_
