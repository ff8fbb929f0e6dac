// `pldvo run --dataset DIR [--format F] [--camera FILE|tum_fr1|tum_fr2|tum_fr3] [--config FILE]
//            [--set key=value]... --out OUT`: the odometry on a dataset (docs/odometry.md); the run
// loop and its outputs are SequenceRunner's (backend/odometry/sequence_runner.h).
// Config precedence: defaults < --config file < --format / --camera < --set.
// Exit codes (docs/reliability.md): 0 done; 1 a fatal input or output fault (dataset files,
// camera, output folder, a failed write, no frame tracked at all); 2 a usage or config error.
#include <gflags/gflags.h>

#include <exception>
#include <iostream>
#include <memory>
#include <string>

#include "backend/odometry/odometry_config.h"
#include "backend/odometry/sequence_runner.h"
#include "core/config_io.h"
#include "core/dataset.h"
#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"
#include "experiments/evaluation/run_outputs.h"

DEFINE_int32(max_frames, 0, "Process only the first N frames (0 = all).");
DEFINE_bool(progress, true, "Show a progress bar when stderr is a terminal.");
DEFINE_bool(realtime, false,
            "Feed the frames at their timestamps, as a live camera does, and drop what the "
            "odometry cannot take in time (summary.json dropped_frames).");
DEFINE_bool(list_config, false, "Print every config key with its default and doc, then exit.");

namespace pldvo {
namespace {

OdometryConfig LoadRunConfig(const CommandContext& context) {
  OdometryConfig config;
  if (!FLAGS_config.empty()) LoadConfigYaml(FLAGS_config, &config);
  if (!gflags::GetCommandLineFlagInfoOrDie("format").is_default) {
    config.dataset.format = FLAGS_format;
  }
  if (!FLAGS_camera.empty()) config.dataset.camera = FLAGS_camera;
  ApplyOverrides(context.config_overrides, &config);
  CheckOptionsOrThrow(config, "config");
  return config;
}

int RunOdometryCommand(const CommandContext& context) {
  if (FLAGS_list_config) {
    std::cout << DescribeConfig(OdometryConfig());
    return 0;
  }
  if (FLAGS_dataset.empty() || FLAGS_out.empty()) {
    std::cerr << "pldvo run: --dataset DIR and --out OUT are required (pldvo run --help)\n";
    return 2;
  }
  OdometryConfig config;
  try {
    config = LoadRunConfig(context);
  } catch (const std::exception& e) {
    std::cerr << "pldvo run: " << e.what() << "\n";
    return 2;
  }
  try {
    const std::unique_ptr<Dataset> dataset = OpenDataset(FLAGS_dataset, config.dataset);
    RunOutputs outputs(FLAGS_out, config.output, dataset.get());
    SequenceRunOptions options;
    options.out_dir = FLAGS_out;
    options.dataset_label = FLAGS_dataset;
    options.config_label = FLAGS_config;
    options.max_frames = FLAGS_max_frames;
    options.progress = FLAGS_progress;
    options.realtime = FLAGS_realtime;
    SequenceRunner runner(*dataset, config, options, &outputs);
    const SequenceRunResult result = runner.Run();
    PrintRunReport(result, std::cout);
    if (result.frames > 0 && result.tracked == 0) {
      std::cerr << "pldvo run: no frame was tracked (" << result.failed
                << " failed to load); check the camera and the messages above\n";
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "\npldvo run: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

PLDVO_REGISTER_COMMAND("run", "Monocular odometry with points and lines on a dataset.",
                       RunOdometryCommand, "dataset", "format", "camera", "config", "out");

}  // namespace pldvo
