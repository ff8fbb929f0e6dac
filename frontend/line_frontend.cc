#include "frontend/line_frontend.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <stdexcept>
#include <string>

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

  frame.descriptors = cv::Mat::zeros(static_cast<int>(frame.segments.size()), 32, CV_8U);
  frame.described.assign(frame.segments.size(), 0);
  // The caller may reuse an 8-bit input's buffer for its next frame.
  frame.gray = gray.data == image.data ? gray.clone() : gray;
  if (!options_.descriptor.on_demand) {
    std::vector<int> all(frame.segments.size());
    std::iota(all.begin(), all.end(), 0);
    Describe(all, &frame);
  }
  if (frame.FullyDescribed()) frame.gray.release();
  return frame;
}

void LineFrontend::Describe(const std::vector<int>& indices, LineFrame* frame) {
  std::vector<int> missing;
  for (int i : indices) {
    if (!frame->described.at(i)) missing.push_back(i);
  }
  if (!missing.empty()) {
    if (frame->gray.empty()) {
      throw std::invalid_argument(std::string(__FILE__) +
                                  ": LineFrame has undescribed segments but no image");
    }
    const WallClock::time_point start = WallClock::now();
    describer_.DescribeRows(frame->gray, frame->segments, missing, &frame->descriptors);
    for (int i : missing) frame->described[i] = 1;
    frame->timing.description_ms += MsSince(start);
  }
  if (frame->FullyDescribed()) frame->gray.release();
}

std::vector<LineMatch> LineFrontend::Match(LineFrame* keyframe, LineFrame* frame,
                                           const SegmentPredictor& predictor,
                                           LineFrontendTiming* timing) {
  for (const LineFrame* lines : {keyframe, frame}) {
    if (lines->described.size() != lines->segments.size() ||
        lines->descriptors.rows != static_cast<int>(lines->segments.size())) {
      throw std::invalid_argument(std::string(__FILE__) +
                                  ": a LineFrame needs one descriptor row and one `described` "
                                  "flag per segment (LineFrontend::Process makes them)");
    }
  }
  WallClock::time_point start = WallClock::now();
  const std::vector<std::vector<int>> gated =
      matcher_.Gate(keyframe->segments, frame->segments, predictor);
  double matching_ms = MsSince(start);
  // Describe what the descriptor test will read: the frame's gated segments, and the keyframe's
  // segments at its first need all at once (it is matched against many frames, and every pass
  // recomputes the descriptor's image pyramid and gradients).
  std::vector<int> cur_needed;
  bool ref_needed = false;
  for (size_t r = 0; r < gated.size(); ++r) {
    if (gated[r].empty()) continue;
    ref_needed = ref_needed || !keyframe->described[r];
    cur_needed.insert(cur_needed.end(), gated[r].begin(), gated[r].end());
  }
  std::sort(cur_needed.begin(), cur_needed.end());
  cur_needed.erase(std::unique(cur_needed.begin(), cur_needed.end()), cur_needed.end());
  const double described_before = keyframe->timing.description_ms + frame->timing.description_ms;
  if (ref_needed) {
    std::vector<int> all(keyframe->segments.size());
    std::iota(all.begin(), all.end(), 0);
    Describe(all, keyframe);
  }
  Describe(cur_needed, frame);
  const double description_ms =
      keyframe->timing.description_ms + frame->timing.description_ms - described_before;
  start = WallClock::now();
  std::vector<LineMatch> matches =
      matcher_.Select(gated, keyframe->descriptors, frame->descriptors, frame->segments.size());
  matching_ms += MsSince(start);
  if (timing != nullptr) {
    timing->description_ms += description_ms;
    timing->matching_ms += matching_ms;
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
