// Test helper: the options of the small synthetic sequence the end-to-end and odometry tests run
// on (lowtex preset, seed 1, 320x240, f = 262.5, 30 fps, 2 render threads).
#ifndef PLDVO_TESTS_SMALL_LOWTEX_OPTIONS_H_
#define PLDVO_TESTS_SMALL_LOWTEX_OPTIONS_H_

#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::test {

inline synthetic::SynthOptions SmallLowtexOptions(int frames) {
  synthetic::SynthOptions options;
  options.preset = "lowtex";
  options.frames = frames;
  options.seed = 1;
  options.width = 320;
  options.height = 240;
  options.fx = options.fy = 262.5;
  options.threads = 2;
  return options;
}

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_SMALL_LOWTEX_OPTIONS_H_
