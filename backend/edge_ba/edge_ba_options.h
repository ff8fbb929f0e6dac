// Options of windowed multi-keyframe edge bundle adjustment (config section backend.edge_ba;
// docs/edge_ba.md).
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_OPTIONS_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_OPTIONS_H_

#include <string>

#include "backend/optimization/ba_linear_solver.h"
#include "core/options.h"
#include "residuals/weighting.h"

namespace pldvo {

// How the 7-DOF gauge of monocular BA (world frame + scale) is fixed.
enum class EdgeBAGauge {
  // The oldest keyframe's pose constant, the distance between the two oldest camera centres held
  // at its input value by a prior (residuals/baseline_prior_residual.h). Removes exactly 7 DOF.
  kFirstPoseAndBaseline,
  // The two oldest poses constant (removes 12 DOF: 5 more than the gauge, so the second pose is
  // not refined).
  kFirstTwoPoses,
};
inline const ChoiceNames<EdgeBAGauge>& EdgeBAGaugeNames() {
  static const ChoiceNames<EdgeBAGauge> names = {
      {"first_pose_and_baseline", EdgeBAGauge::kFirstPoseAndBaseline},
      {"first_two_poses", EdgeBAGauge::kFirstTwoPoses}};
  return names;
}

// What happens to a line that is also observed by keyframes that have left the window
// (EdgeBALine::anchored).
enum class EdgeBALeavingLines {
  kFixed,  // held constant at its input estimate: its in-window observations constrain poses
  kFree,   // optimised from its in-window observations only (older information dropped)
};
inline const ChoiceNames<EdgeBALeavingLines>& EdgeBALeavingLinesNames() {
  static const ChoiceNames<EdgeBALeavingLines> names = {{"fixed", EdgeBALeavingLines::kFixed},
                                                        {"free", EdgeBALeavingLines::kFree}};
  return names;
}

using EdgeBALinearSolver = BALinearSolver;

struct EdgeBAOptions {
  // Off by default: the odometry runs without BA unless asked.
  bool enabled = false;
  // Keyframes per window (the newest `window` keyframes of a snapshot). >= 2.
  int window = 5;
  // Levenberg-Marquardt iterations per window. Measured on 150-line windows with triangulated
  // initial lines (experiments/benchmarks/edge_ba_benchmark.cc): 3 and 5 keyframes converge in
  // 7-10 iterations, 7 keyframes need about 16 (docs/edge_ba.md, "Measurements").
  int max_iterations = 20;
  // Ceres' relative cost-change tolerance.
  double function_tolerance = 1e-6;
  // Robust loss on every whitened pixel residual; threshold in whitened units (sigmas). 1.345 is
  // Huber's 95%-efficiency constant, as in tracking.
  RobustLossKind robust_loss = RobustLossKind::kHuber;
  double robust_threshold = 1.345;
  // Where the robust loss is applied. true: one residual block per (keyframe, line) with the
  // loss row-wise inside the cost function (square-root form, residuals/robustify.h, as in
  // tracking). false: one residual block per pixel with the loss given to Ceres, which applies
  // Triggs' second-order correction; measured to converge in fewer iterations when many rows
  // start beyond the Huber threshold (docs/edge_ba.md).
  bool batch_pixels = false;
  // Pixel noise used when an observation's sigma_px is <= 0 (full-resolution pixels).
  double default_sigma_px = 1.0;
  // At most this many pixels of one observation enter the problem (evenly subsampled along the
  // given order); bounds the cost of long edges. 0 = all.
  int max_pixels_per_observation = 16;
  EdgeBAGauge gauge = EdgeBAGauge::kFirstPoseAndBaseline;
  // sigma_b of the baseline prior as a fraction of the baseline. Any value > 0 gives the same
  // optimum (the data are scale-invariant); 1e-2 keeps the normal equations well conditioned.
  double baseline_prior_sigma_ratio = 1e-2;
  EdgeBALeavingLines lines_leaving_window = EdgeBALeavingLines::kFixed;
  // A free line needs observations in at least this many window keyframes (>= 2: one view
  // leaves 2 of its 4 DOF unconstrained).
  int min_observing_keyframes = 2;
  // ... and a largest angle between its back-projected planes of at least this many degrees
  // (planes that nearly coincide leave the line's depth in the plane unconstrained).
  double min_plane_angle_deg = 2.0;
  // Motion prior (backend/edge_ba/edge_ba_motion_prior.h) between consecutive window keyframes that
  // carry a tracked relative pose (EdgeBAKeyframe::has_motion_prior): translation sigma
  // motion_prior_translation_ratio * |t| (scale-free), rotation sigma motion_prior_rotation_deg.
  // Without it, the line-only problem of a short-baseline window moved well-tracked keyframes by
  // centimetres (docs/edge_ba.md, "In the odometry").
  bool motion_prior = true;
  double motion_prior_translation_ratio = 0.01;
  double motion_prior_rotation_deg = 0.1;
  EdgeBALinearSolver linear_solver = EdgeBALinearSolver::kSparseSchur;
  int num_threads = 1;
  // Snapshots waiting in EdgeBundleAdjuster's queue; a new one beyond this drops the oldest.
  int max_queue = 2;
  // After a successful solve, the optimised lines' marginal covariances (ceres::Covariance,
  // tangent space of LineManifold<3>) are computed on the solving thread, and the odometry fuses
  // the lines the current keyframe observes into its depth map (docs/edge_ba.md).
  bool line_depth_feedback = true;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("enabled", &enabled, "Run windowed edge bundle adjustment beside tracking.");
    v.Field("window", &window, "Keyframes per window (>= 2).");
    v.Field("max_iterations", &max_iterations, "Levenberg-Marquardt iterations per window.");
    v.Field("function_tolerance", &function_tolerance, "Relative cost-change tolerance.");
    v.Choice("robust_loss", &robust_loss, RobustLossKindNames(),
             "Robust loss on each whitened pixel residual: none, huber, cauchy.");
    v.Field("robust_threshold", &robust_threshold, "Scale of the robust loss in sigmas.");
    v.Field("batch_pixels", &batch_pixels,
            "One residual block per observation with a row-wise loss (true) or one per pixel "
            "with Ceres' loss (false).");
    v.Field("default_sigma_px", &default_sigma_px,
            "Pixel noise (px) of observations that give none.");
    v.Field("max_pixels_per_observation", &max_pixels_per_observation,
            "Edge pixels per observation used (evenly subsampled); 0 = all.");
    v.Choice("gauge", &gauge, EdgeBAGaugeNames(),
             "Gauge: first_pose_and_baseline (oldest pose fixed + baseline prior) or "
             "first_two_poses.");
    v.Field("baseline_prior_sigma_ratio", &baseline_prior_sigma_ratio,
            "sigma of the baseline prior as a fraction of the baseline.");
    v.Choice("lines_leaving_window", &lines_leaving_window, EdgeBALeavingLinesNames(),
             "Lines also seen by keyframes that left the window: fixed or free.");
    v.Field("min_observing_keyframes", &min_observing_keyframes,
            "Window keyframes that must observe a free line (>= 2).");
    v.Field("min_plane_angle_deg", &min_plane_angle_deg,
            "Smallest largest-angle between a free line's back-projected planes (degrees).");
    v.Field("motion_prior", &motion_prior,
            "Prior on consecutive keyframes' relative pose from tracking (default true).");
    v.Field("motion_prior_translation_ratio", &motion_prior_translation_ratio,
            "Translation sigma of the motion prior as a fraction of |t| (default 0.01).");
    v.Field("motion_prior_rotation_deg", &motion_prior_rotation_deg,
            "Rotation sigma of the motion prior, degrees (default 0.1).");
    v.Choice("linear_solver", &linear_solver, BALinearSolverNames(),
             "sparse_schur (SuiteSparse, lines eliminated first), dense_schur, "
             "sparse_normal_cholesky.");
    v.Field("num_threads", &num_threads, "Ceres threads per solve.");
    v.Field("max_queue", &max_queue, "Pending windows in the worker's queue (oldest dropped).");
    v.Field("line_depth_feedback", &line_depth_feedback,
            "Line covariances after each solve; optimised lines fused into the current "
            "keyframe's depth map (default true).");
  }
  // "" when valid, otherwise what is wrong (names the key).
  std::string Check() const;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_OPTIONS_H_
