// The line frontend (seed paper Sec. VI-A(1)): per frame, detection on an octave pyramid
// (LineDetector), merging of broken segments (LineMerger) and LBD description (LbdDescriber);
// per keyframe/frame pair, bucketed descriptor matching (LineMatcher); per keyframe, edge
// tracing of the matched lines (EdgeTracer). Each stage is timed per frame into
// LineFrontendTiming (the components of the paper's Table III). Frames arrive as CV_32F
// (0..255) or CV_8U images; the 8-bit conversion happens once per frame.
#ifndef PLDVO_FRONTEND_LINE_FRONTEND_H_
#define PLDVO_FRONTEND_LINE_FRONTEND_H_

#include <opencv2/core.hpp>
#include <vector>

#include "frontend/edge_tracer.h"
#include "frontend/lbd_describer.h"
#include "frontend/line_detector.h"
#include "frontend/line_frontend_options.h"
#include "frontend/line_matcher.h"
#include "frontend/line_merger.h"
#include "frontend/line_segment.h"

namespace pldvo {

// Wall-clock milliseconds per component of one frame.
struct LineFrontendTiming {
  double detection_ms = 0.0;    // 8-bit conversion, octave pyramid and detection
  double merging_ms = 0.0;      // merging, the length filter and the refit (lines.refiner)
  double description_ms = 0.0;  // LBD
  double matching_ms = 0.0;     // keyframe -> frame matching
  double tracing_ms = 0.0;      // edge tracing (keyframes only)
  int num_detected = 0;         // segments before merging
  int num_lines = 0;            // segments after merging
  int num_matches = 0;
  // Detection + merging + description + matching (+ tracing).
  double total_ms() const {
    return detection_ms + merging_ms + description_ms + matching_ms + tracing_ms;
  }
};

// The lines of one frame.
struct LineFrame {
  cv::Size image_size;
  std::vector<LineSegment> segments;  // merged, longest first
  cv::Mat descriptors;                // segments.size() x 32, CV_8U
  LineFrontendTiming timing;          // detection, merging and description of this frame
};

class LineFrontend {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit LineFrontend(const LineFrontendOptions& options);

  // Detects, merges and describes the lines of an image (CV_32F 0..255 or CV_8U, one channel).
  // Not thread-safe; use one frontend per thread.
  LineFrame Process(const cv::Mat& image);

  // Matches a keyframe's lines into a frame's; adds the matching time and count to `timing`
  // when given. `predictor` may be empty (see line_matcher.h).
  std::vector<LineMatch> Match(const LineFrame& keyframe, const LineFrame& frame,
                               const SegmentPredictor& predictor = nullptr,
                               LineFrontendTiming* timing = nullptr) const;

  // Traces the keyframe lines that appear as ref_index in `matches` (each once).
  EdgeTrace TraceMatched(const LineFrame& keyframe, const std::vector<LineMatch>& matches,
                         LineFrontendTiming* timing = nullptr) const;

  const LineFrontendOptions& options() const { return options_; }

 private:
  LineFrontendOptions options_;
  LineDetector detector_;
  LineMerger merger_;
  LbdDescriber describer_;
  LineMatcher matcher_;
  EdgeTracer tracer_;
};

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_FRONTEND_H_
