// `pldvo info --dataset DIR [--format F] [--camera C]`: what OpenDataset makes of a folder
// (docs/datasets.md), checked by loading the first frame. `--set ground_truth=FILE` overrides the
// ground truth as in DatasetOptions.
#include <gflags/gflags.h>

#include <algorithm>
#include <exception>
#include <iomanip>
#include <iostream>
#include <opencv2/core.hpp>

#include "core/config_io.h"
#include "core/constant_velocity_start.h"
#include "core/dataset.h"
#include "core/evaluation.h"
#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"

namespace pldvo {
namespace {

int RunInfo(const CommandContext& context) {
  if (FLAGS_dataset.empty()) {
    std::cerr << "pldvo info: --dataset is required\n";
    return 2;
  }
  try {
    DatasetOptions options;
    options.format = FLAGS_format;
    options.camera = FLAGS_camera;
    ApplyOverrides(context.config_overrides, &options);
    CheckOptionsOrThrow(options, "dataset options");
    const std::unique_ptr<Dataset> dataset = OpenDataset(FLAGS_dataset, options);
    const PinholeCamera& camera = dataset->camera();
    const int n = dataset->size();
    const double first = dataset->timestamp(0), last = dataset->timestamp(n - 1);
    const double duration = last - first;
    std::cout << std::setprecision(6) << std::fixed;
    std::cout << "dataset:      " << FLAGS_dataset << "\n"
              << "format:       " << dataset->format() << "\n"
              << "frames:       " << n << "\n"
              << "duration:     " << duration << " s\n"
              << "fps:          " << (duration > 0.0 ? (n - 1) / duration : 0.0) << "\n"
              << "first/last:   " << first << " / " << last << " s\n"
              << "resolution:   " << camera.width << "x" << camera.height << "\n"
              << "camera:       fx " << camera.fx << " fy " << camera.fy << " cx " << camera.cx
              << " cy " << camera.cy << " (undistorted pinhole)\n";
    const Trajectory* ground_truth = dataset->ground_truth();
    if (ground_truth != nullptr && !ground_truth->empty()) {
      std::cout << "ground truth: yes, " << ground_truth->size() << " poses, "
                << ground_truth->front().timestamp << " .. " << ground_truth->back().timestamp
                << " s\n";
      const int constant = ConstantVelocityStartPoses(
          *ground_truth, EvaluationOptions().constant_velocity_tolerance);
      if (constant > 0) {
        std::cout << "              its first " << constant
                  << " poses move at one constant velocity: extrapolated, not measured?"
                  << " (docs/evaluation.md, \"Extrapolated ground truth\")\n";
      }
    } else {
      std::cout << "ground truth: no\n";
    }
    const Frame frame = dataset->Load(0);
    double min_value = 0.0, max_value = 0.0;
    cv::minMaxLoc(frame.image, &min_value, &max_value);
    std::cout << "first frame:  " << frame.path << " (" << frame.image.cols << "x"
              << frame.image.rows << ", intensities " << std::setprecision(1) << min_value << " .. "
              << max_value << ", mean " << cv::mean(frame.image)[0] << ")\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "pldvo info: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

PLDVO_REGISTER_COMMAND("info",
                       "Summary of a dataset folder (format, frames, camera, ground truth).",
                       RunInfo, "dataset", "format", "camera");

}  // namespace pldvo
