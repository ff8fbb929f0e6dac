// `pldvo mapeval`: evaluates the semi-dense mapping (photometric vs line-guided stereo, 3D line
// regularisation, NEES, propagation) on a synthetic sequence with GT poses and depth and prints
// the table of docs/mapping.md.
//   pldvo mapeval [--set num_frames=15 --set synth.seed=2 --set mapping.sigma_intensity=2]
//                 [--out DIR]   (writes the keyframe's inverse-depth PNG and PLY)
#include <gflags/gflags.h>

#include <chrono>
#include <exception>
#include <iostream>

#include "core/config_io.h"
#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"
#include "experiments/evaluation/mapping_evaluation.h"

DEFINE_bool(mapeval_list_options, false,
            "Print every --set key of mapeval with its default and doc, then exit.");

namespace pldvo {
namespace {

int RunMapEval(const CommandContext& context) {
  try {
    MapEvalConfig config;
    if (FLAGS_mapeval_list_options) {
      std::cout << DescribeConfig(config);
      return 0;
    }
    ApplyOverrides(context.config_overrides, &config);
    CheckOptionsOrThrow(config, "mapeval");
    const auto start = std::chrono::steady_clock::now();
    config.out_dir = FLAGS_out;
    const MapEvalResult result = RunMapEvaluation(config);
    std::cout << FormatMapEvalTable(result);
    std::cout << "total "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
              << " s\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "pldvo mapeval: " << error.what() << "\n";
    return 1;
  }
}

PLDVO_REGISTER_COMMAND("mapeval", "Semi-dense mapping evaluation on a synthetic sequence.",
                       RunMapEval, "out");

}  // namespace
}  // namespace pldvo
