#include "frontend/line_frontend.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "core/wall_clock.h"
#include "frontend/line_refiner.h"

namespace pldvo {
namespace {

const LineFrontendOptions& Checked(const LineFrontendOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument("LineFrontendOptions: " + error);
  return options;
}

}  // namespace

LineFrontend::LineFrontend(const LineFrontendOptions& options)
    : options_(Checked(options)),
      detector_(options.detector),
      merger_(options.merger, options.detector.endpoint_sigma_px),
      describer_(options.descriptor),
      matcher_(options.matcher),
      tracer_(options.tracer) {}

LineFrame LineFrontend::Process(const cv::Mat& image) {
  LineFrame frame;
  WallClock::time_point start = WallClock::now();
  const cv::Mat gray = ToGray8(image);
  frame.image_size = gray.size();
  const std::vector<cv::Mat> octaves =
      BuildOctaves(gray, options_.detector.first_octave + options_.detector.num_octaves);
  const std::vector<LineSegment> detected = detector_.Detect(octaves);
  frame.timing.detection_ms = MsSince(start);
  frame.timing.num_detected = static_cast<int>(detected.size());

  start = WallClock::now();
  frame.segments = merger_.Merge(detected);
  if (options_.refiner.enabled) {
    RefineSegmentsToEdges(gray, options_.refiner, options_.detector.endpoint_sigma_px,
                          &frame.segments);
  }
  frame.timing.merging_ms = MsSince(start);
  frame.timing.num_lines = static_cast<int>(frame.segments.size());

  start = WallClock::now();
  frame.descriptors = describer_.Describe(gray, frame.segments);
  frame.timing.description_ms = MsSince(start);
  return frame;
}

std::vector<LineMatch> LineFrontend::Match(const LineFrame& keyframe, const LineFrame& frame,
                                           const SegmentPredictor& predictor,
                                           LineFrontendTiming* timing) const {
  const WallClock::time_point start = WallClock::now();
  std::vector<LineMatch> matches = matcher_.Match(keyframe.segments, keyframe.descriptors,
                                                  frame.segments, frame.descriptors, predictor);
  if (timing != nullptr) {
    timing->matching_ms += MsSince(start);
    timing->num_matches += static_cast<int>(matches.size());
  }
  return matches;
}

EdgeTrace LineFrontend::TraceMatched(const LineFrame& keyframe,
                                     const std::vector<LineMatch>& matches,
                                     LineFrontendTiming* timing) const {
  const WallClock::time_point start = WallClock::now();
  std::vector<int> ids;
  ids.reserve(matches.size());
  for (const LineMatch& match : matches) ids.push_back(match.ref_index);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  EdgeTrace trace = tracer_.Trace(keyframe.segments, ids, keyframe.image_size);
  if (timing != nullptr) timing->tracing_ms += MsSince(start);
  return trace;
}

}  // namespace pldvo
