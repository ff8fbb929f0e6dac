// `pldvo eval --gt FILE --est FILE [--json] [--motion_errors CSV]`: ATE, RPE, coverage, scale
// drift and the pooled rotation ratio of an estimated trajectory against ground truth, both in TUM
// format (docs/evaluation.md).
// `--set key=value` sets the EvaluationOptions (max_time_diff, rpe_delta, align_scale,
// scale_window, constant_velocity_tolerance, skip_constant_velocity_start).
#include <gflags/gflags.h>

#include <cmath>
#include <exception>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/config_io.h"
#include "core/evaluation.h"
#include "core/trajectory_io.h"
#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"

DEFINE_string(gt, "", "Ground-truth trajectory, TUM format (timestamp tx ty tz qx qy qz qw).");
DEFINE_string(est, "", "Estimated trajectory, TUM format.");
DEFINE_string(motion_errors, "",
              "Also write the error of every frame-to-frame motion to this CSV "
              "(docs/evaluation.md, \"Per-frame motion errors\").");

namespace pldvo {
namespace {

// JSON has no NaN: an RPE without pairs is written as null.
nlohmann::json NumberOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

int RunEval(const CommandContext& context) {
  if (FLAGS_gt.empty() || FLAGS_est.empty()) {
    std::cerr << "pldvo eval: --gt and --est are required\n";
    return 2;
  }
  try {
    EvaluationOptions options;
    ApplyOverrides(context.config_overrides, &options);
    CheckOptionsOrThrow(options, "eval options");
    const Trajectory ground_truth = ReadTrajectoryTum(FLAGS_gt);
    const Trajectory estimate = ReadTrajectoryTum(FLAGS_est);
    const EvaluationResult result = EvaluateTrajectory(ground_truth, estimate, options);
    const std::vector<FrameMotionError> motion_errors =
        EvaluateFrameMotion(ground_truth, estimate, result.scale, options.max_time_diff);
    const double rotation_ratio = PooledRotationRatio(motion_errors);
    if (!FLAGS_motion_errors.empty()) {
      std::ofstream file(FLAGS_motion_errors);
      WriteFrameMotionErrorsCsv(motion_errors, file);
      if (!file) throw std::runtime_error("cannot write " + FLAGS_motion_errors);
    }
    if (FLAGS_json) {
      nlohmann::json json;
      json["ate_m"] = result.ate_m;
      json["rpe_cm_s"] = NumberOrNull(result.rpe_cm_s);
      json["rpe_deg_s"] = NumberOrNull(result.rpe_deg_s);
      json["rpe_cm_s_still"] = NumberOrNull(result.rpe_cm_s_still);
      json["scale"] = result.scale;
      json["coverage"] = result.coverage;
      json["scale_drift"] = NumberOrNull(result.scale_drift);
      json["window_scales"] = result.window_scales;
      json["num_pairs"] = result.num_pairs;
      json["num_associated"] = result.num_associated;
      json["num_estimate"] = estimate.size();
      json["num_ground_truth"] = ground_truth.size();
      json["ground_truth_constant_velocity_start"] = result.constant_velocity_start_poses;
      json["skipped_ground_truth_poses"] = result.skipped_ground_truth_poses;
      json["rotation_ratio"] = NumberOrNull(rotation_ratio);
      std::cout << json.dump() << "\n";
      return 0;
    }
    std::cout << std::fixed << std::setprecision(4) << "ATE (Sim(3)-aligned RMSE): " << result.ate_m
              << " m\n"
              << "RPE translation:           " << std::setprecision(3) << result.rpe_cm_s
              << " cm/s  (delta " << options.rpe_delta << " s, " << result.num_pairs << " pairs)\n"
              << "RPE translation, still:    " << result.rpe_cm_s_still
              << " cm/s  (an estimate that never moves)\n"
              << "RPE rotation:              " << result.rpe_deg_s << " deg/s\n"
              << "rotation ratio (est / gt): " << rotation_ratio << "\n"
              << "scale (gt per est unit):   " << std::setprecision(6) << result.scale << "\n"
              << "coverage:                  " << std::setprecision(3) << result.coverage << "  ("
              << result.num_associated << " of " << estimate.size()
              << " estimate poses associated, " << ground_truth.size() << " ground-truth poses)\n"
              << "scale drift (max / min):   " << std::setprecision(3) << result.scale_drift
              << "  (estimate units per gt metre, per " << options.scale_window << " s:";
    for (double scale : result.window_scales) std::cout << " " << std::setprecision(3) << scale;
    std::cout << ")\n";
    if (result.constant_velocity_start_poses > 0) {
      std::cout << "ground truth:              its first " << result.constant_velocity_start_poses
                << " poses move at one constant velocity (extrapolated?); "
                << (result.skipped_ground_truth_poses > 0
                        ? "evaluated from the last of them on\n"
                        : "included (--set skip_constant_velocity_start=true leaves them out)\n");
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "pldvo eval: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

PLDVO_REGISTER_COMMAND("eval",
                       "ATE, RPE and coverage of a TUM-format trajectory against ground truth.",
                       RunEval, "json");

}  // namespace pldvo
