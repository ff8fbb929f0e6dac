// The line frontend (seed paper Sec. VI-A(1)): per frame, detection on an octave pyramid
// (LineDetector), merging of broken segments (LineMerger) and LBD description (LbdDescriber);
// per keyframe/frame pair, bucketed descriptor matching (LineMatcher); per keyframe, edge
// tracing of the matched lines (EdgeTracer). Each stage is timed per frame into
// LineFrontendTiming (the components of the paper's Table III). Frames arrive as CV_32F
// (0..255) or CV_8U images; the 8-bit conversion happens once per frame.
#ifndef PLDVO_FRONTEND_LINE_FRONTEND_H_
#define PLDVO_FRONTEND_LINE_FRONTEND_H_

#include <algorithm>
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

// The lines of one frame. With lines.descriptor.on_demand its segments are described when a
// match needs them (LineFrontend::Match); `gray` is kept for that until every segment is
// described.
struct LineFrame {
  cv::Size image_size;
  std::vector<LineSegment> segments;  // merged, longest first
  cv::Mat descriptors;                // segments.size() x 32, CV_8U; row i valid if described[i]
  std::vector<char> described;        // one flag per segment
  cv::Mat gray;                       // the 8-bit image while some segment is undescribed
  LineFrontendTiming timing;          // detection, merging and description of this frame

  bool FullyDescribed() const {
    return std::find(described.begin(), described.end(), 0) == described.end();
  }
};

class LineFrontend {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit LineFrontend(const LineFrontendOptions& options);

  // Detects, merges and describes the lines of an image (CV_32F 0..255 or CV_8U, one channel);
  // with options.descriptor.on_demand the description is left to Match. Not thread-safe; use one
  // frontend per thread.
  LineFrame Process(const cv::Mat& image);

  // Matches a keyframe's lines into a frame's, first describing what has no descriptor yet: the
  // frame's segments that pass some geometric gate, and all of the keyframe's once one of them
  // does; adds the description and matching times and the match count to `timing` when given.
  // `predictor` may be empty (line_matcher.h).
  std::vector<LineMatch> Match(LineFrame* keyframe, LineFrame* frame,
                               const SegmentPredictor& predictor = nullptr,
                               LineFrontendTiming* timing = nullptr);

  // Describes the segments listed in `indices` that have no descriptor yet.
  void Describe(const std::vector<int>& indices, LineFrame* frame);

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
