// Test helper: the small lowtex sequence (tests/small_lowtex_options.h) rendered (through the
// test render cache, tests/render_cache.h), with every frame as CV_32F and frame 0's depth.
#ifndef PLDVO_TESTS_BACKEND_RENDERED_SEQUENCE_H_
#define PLDVO_TESTS_BACKEND_RENDERED_SEQUENCE_H_

#include <opencv2/core.hpp>
#include <vector>

#include "experiments/synthetic/synthetic_sequence.h"
#include "tests/render_cache.h"
#include "tests/small_lowtex_options.h"

namespace pldvo::test {

struct RenderedSequence {
  synthetic::SyntheticSequence sequence;
  std::vector<cv::Mat> images;  // CV_32F
  cv::Mat first_depth;          // CV_32F metres, frame 0
};

inline RenderedSequence RenderLowtexSequence(int frames) {
  const synthetic::SynthOptions options = SmallLowtexOptions(frames);
  RenderedSequence result;
  result.sequence = synthetic::MakeSequence(options);
  for (int i = 0; i < frames; ++i) {
    cv::Mat image;
    const synthetic::RenderedFrame frame = RenderFrameForTest(result.sequence, i);
    frame.image.convertTo(image, CV_32F);
    result.images.push_back(image);
    if (i == 0) result.first_depth = frame.depth;
  }
  return result;
}

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_BACKEND_RENDERED_SEQUENCE_H_
