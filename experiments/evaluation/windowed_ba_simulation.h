// A hand-made scene for windowed photometric + line bundle adjustment with exact ground truth
// (tests/backend/windowed_ba_test.cc, experiments/benchmarks/windowed_ba_benchmark.cc): a room
// corner of planes (back wall, floor, left wall) and a free-standing panel, each textured with
// seeded value noise, the back wall with painted step edges along 3D lines; rendered by
// analytic ray casting at pixel centres, blurred (the pixel response), with Gaussian noise and a
// per-keyframe affine brightness. The first keyframe's camera is the world frame. Inputs: the
// poses, brightness and inverse depths perturbed by seeded Gaussian noise (the oldest pose and
// brightness exact: they are the gauge), the line observations from the true geometry.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_WINDOWED_BA_SIMULATION_H_
#define PLDVO_EXPERIMENTS_EVALUATION_WINDOWED_BA_SIMULATION_H_

#include <cstdint>
#include <vector>

#include "backend/windowed_ba/windowed_ba_solver.h"
#include "backend/windowed_ba/windowed_ba_window.h"

namespace pldvo {

struct WindowedBASimulationOptions {
  int width = 320;
  int height = 240;
  double focal = 262.5;  // px (the 640x480 f = 525 camera at half resolution)
  int num_keyframes = 5;
  double spacing = 0.1;                 // m between consecutive keyframe centres (mostly sideways)
  double yaw_step_deg = -1.0;           // rotation about the vertical per keyframe
  double noise_sigma = 1.0;             // gray levels
  double blur_sigma_px = 0.8;           // Gaussian pixel response
  double candidate_min_gradient = 6.0;  // gray levels / px: which pixels become candidates
  // True brightness of keyframe k > 0: a = gain_step * (-1)^k, b = bias_step * k.
  double gain_step = 0.05;
  double bias_step = 3.0;
  // Perturbation of the inputs (keyframes k > 0; every point's inverse depth).
  double translation_sigma = 0.0025;  // m per axis
  double rotation_sigma_deg = 0.1;    // per axis
  double idepth_relative_sigma = 0.025;
  // The idepth_var given with each point: (idepth_var_relative * idepth)^2.
  double idepth_var_relative = 0.025;
  double line_endpoint_sigma_px = 0.5;  // Sigma_l of the line observations (FitLine)
  std::uint64_t seed = 1;
};

struct WindowedBASimulation {
  WindowedBAWindow window;  // the perturbed inputs
  std::vector<SE3> true_cam_from_world;
  std::vector<AffineBrightness> true_brightness;
  // Per keyframe, per point of window.keyframes[k].points: the true inverse depth.
  std::vector<std::vector<double>> true_idepths;
};

WindowedBASimulation SimulateWindowedBAWindow(const WindowedBASimulationOptions& options);

// Errors of an estimate against the ground truth, up to the gauge: the oldest camera is the
// world origin in both, and the estimate's scale s is fitted (least squares on the camera
// centres, c_true ~ s c_est), so inverse depths compare as idepth_est / s.
struct WindowedBAErrors {
  double rotation_rms_deg = 0.0;        // keyframes k > 0
  double translation_rms_m = 0.0;       // keyframes k > 0, after scaling
  double idepth_relative_rms = 0.0;     // over the given points
  double idepth_relative_median = 0.0;  // median of |relative error| over the given points
  double scale = 1.0;
};
// `cam_from_world` per window keyframe (oldest first, the simulation's keyframes), `points` the
// refined (or input) inverse depths of some points.
WindowedBAErrors EvaluateWindowedBA(const WindowedBASimulation& simulation,
                                    const std::vector<SE3>& cam_from_world,
                                    const std::vector<WindowedBAResultPoint>& points);
// The same for the simulation's inputs, over the same points.
WindowedBAErrors EvaluateWindowedBAInput(const WindowedBASimulation& simulation,
                                         const std::vector<WindowedBAResultPoint>& points);

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_WINDOWED_BA_SIMULATION_H_
