// Options of windowed photometric + line bundle adjustment (docs/windowed_ba.md). One typed
// struct: read from YAML and `--set` through VisitFields (core/config_io.h, unknown keys are
// errors), validated by Check(). The odometry's config holds it as `backend.windowed_ba`
// (backend/odometry/odometry_config.h); the odometry runs it when `enabled` (docs/windowed_ba.md,
// "In the odometry").
#ifndef PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_OPTIONS_H_
#define PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_OPTIONS_H_

#include <string>

#include "backend/optimization/ba_linear_solver.h"
#include "backend/optimization/thread_priority.h"
#include "backend/windowed_ba/leaving_keyframe.h"
#include "core/options.h"
#include "residuals/affine_brightness.h"
#include "residuals/photometric_residual.h"
#include "residuals/weighting.h"

namespace pldvo {

// The host pixels of one point's photometric residual (sharing its inverse depth).
enum class WindowedBAPattern {
  kSingle,  // the point's pixel only
  kDso8,    // DSO's 8-pixel pattern (offsets within 2 px), more rows per inverse depth
};
inline const ChoiceNames<WindowedBAPattern>& WindowedBAPatternNames() {
  static const ChoiceNames<WindowedBAPattern> names = {{"single", WindowedBAPattern::kSingle},
                                                       {"dso8", WindowedBAPattern::kDso8}};
  return names;
}

// What the newest keyframe of a window hosts. The window is solved when the newest keyframe's
// first map is published: that map is the previous keyframe's propagated into it, so its points
// repeat the previous keyframe's depths, depth-filter variances and image pairs.
enum class NewestKeyframePoints {
  kHost,         // points with inverse-depth priors, as every other keyframe
  kHostNoPrior,  // points without inverse-depth priors (the priors would count twice)
  kTargetOnly,   // no points (as in DSO, where a new keyframe's points enter later windows)
};
inline const ChoiceNames<NewestKeyframePoints>& NewestKeyframePointsNames() {
  static const ChoiceNames<NewestKeyframePoints> names = {
      {"host", NewestKeyframePoints::kHost},
      {"host_no_prior", NewestKeyframePoints::kHostNoPrior},
      {"target_only", NewestKeyframePoints::kTargetOnly}};
  return names;
}

enum class WindowedBASolver { kCeres, kGaussNewton };
inline const ChoiceNames<WindowedBASolver>& WindowedBASolverNames() {
  static const ChoiceNames<WindowedBASolver> names = {
      {"ceres", WindowedBASolver::kCeres}, {"gauss_newton", WindowedBASolver::kGaussNewton}};
  return names;
}

using WindowedBALinearSolver = BALinearSolver;

struct WindowedBAOptions {
  // Off by default: the odometry runs without the windowed BA unless asked.
  bool enabled = false;
  // The registered problem builder (WindowedBAProblemBuilderRegistry): "windowed_ba" (robust
  // loss row-wise inside the cost functions) or "windowed_ba_ceres_loss" (the loss given to the
  // problem per residual block, i.e. per point pattern and target).
  std::string problem_builder = "windowed_ba";
  // The newest `window` keyframes of a window are optimised (>= 2). 10: the best of 5, 7 and 10
  // on the development set at the shipped keyframe rate, measured in docs/windowed_ba.md.
  int window = 10;
  // Points per window (DSO: ~2000), split evenly over the keyframes; each keyframe's share is
  // chosen by SelectWindowPoints (a grid of cells, best gradient per cell).
  int max_points = 2000;
  // Candidates whose image gradient magnitude is below this (gray levels / px) are not
  // selected: their photometric rows hardly constrain anything.
  double min_gradient = 5.0;
  WindowedBAPattern pattern = WindowedBAPattern::kDso8;
  // A point enters only if it has photometric rows in at least this many other keyframes.
  int min_targets = 1;
  // What the newest keyframe hosts; target_only splits max_points over the others. host measured
  // best on the development set (docs/windowed_ba.md).
  NewestKeyframePoints newest_keyframe_points = NewestKeyframePoints::kHost;
  // Sampling of the target images (residuals/photometric_residual.h): bilinear (as tracking) or
  // bicubic (exact Jacobian).
  ImageInterpolation interpolation = ImageInterpolation::kBilinear;
  // affine: each keyframe's {a, b} (I = e^a L + b) is estimated, the oldest held constant (the
  // brightness gauge), the others with a prior N(input, sigma^2): +-10% and +-10 gray levels,
  // as tracking's prior. none: {a, b} held at their input values.
  BrightnessModel brightness = BrightnessModel::kAffine;
  double brightness_prior_sigma_a = 0.1;
  double brightness_prior_sigma_b = 10.0;
  // A prior N(input idepth, (idepth_prior_scale^2) V) on each point's inverse depth, V the
  // depth filter's variance: the filter's estimate as information. It regularises the depth of a
  // point whose rows hardly constrain it (image gradient across its epipolar lines, one
  // short-baseline target), and with it the poses; 1 takes the filter's variance as it is
  // (docs/windowed_ba.md, "Inverse-depth prior", compares 0, 1 and 10). The priors also carry
  // the inputs' scale, so they trade off against the baseline prior when input poses and depths
  // disagree in scale. 0: no prior (DSO).
  double idepth_prior_scale = 1.0;
  // A robust loss on each inverse-depth prior's whitened residual (in sigmas; threshold
  // idepth_prior_loss_threshold): a filter hypothesis the rows contradict by many sigmas (a wrong
  // stereo or line match, confident) then stops pulling the window's scale. none: Gaussian.
  RobustLossKind idepth_prior_loss = RobustLossKind::kNone;
  double idepth_prior_loss_threshold = 2.0;
  // Whether a row's weight carries the depth filter's variance V: eq. 5's (g^T J_d)^2 V and eq.
  // 6's l^T Sigma_x' l, as in tracking, where the depth is a constant. Here the inverse depth is
  // a variable with V in its prior, so a row's own noise is sigma_I (eq. 5) or the line's
  // Sigma_l (eq. 6); true counts V twice and down-weights exactly the rows that constrain d
  // (docs/windowed_ba.md, "Weights").
  bool depth_variance_in_weights = false;
  // Point-to-line rows (eq. 3) for selected points on edges with a line observation in another
  // window keyframe (off: photometric only).
  bool lines = true;
  // A point's photometric target is left out when its energy (the mean squared whitened residual
  // of its pattern at the input estimate) exceeds outlier_energy_factor^2 times the median
  // energy of the window's targets (DSO's outlier test, Engel et al. PAMI 2018 Sec. 3.3:
  // occlusions, a wrong depth): such rows pull the poses and their robust loss is not convex.
  // 0 = off.
  double outlier_energy_factor = 0.0;
  // What leaves the window (docs/windowed_ba.md): true marginalises the oldest keyframe of a full
  // window into a prior on the poses of the others for the next window (DSO; marginalization.h);
  // false is a fixed lag (a leaving keyframe keeps its last pose, its rows are forgotten).
  bool marginalize = false;
  // Which keyframe leaves a full window (leaving_keyframe.h): oldest (the newest `window`
  // keyframes) or spread (DSO's choice: out of view first, else by the distance score; fixed lag
  // only, since the prior marginalises the oldest). leaving_min_visible: the fraction of a
  // keyframe's points in view of the newest keyframe below which it leaves first.
  LeavingKeyframe leaving = LeavingKeyframe::kOldest;
  double leaving_min_visible = 0.05;
  // sigma_b of the baseline prior (the scale gauge) as a fraction of the baseline. Without
  // inverse-depth priors any value > 0 gives the same optimum (the rows are scale-invariant);
  // 1e-2 keeps the system conditioned.
  double baseline_prior_sigma_ratio = 1e-2;
  // Weighting (eq. 5, eq. 6 covariance models; sigma_I; robust loss and its threshold).
  WeightingOptions weighting;
  // Solver of the built problem: ceres (Levenberg-Marquardt, linear_solver below, inverse
  // depths eliminated first) or gauss_newton (backend/optimization, Schur on the inverse depths).
  WindowedBASolver solver = WindowedBASolver::kCeres;
  WindowedBALinearSolver linear_solver = WindowedBALinearSolver::kSparseSchur;
  int max_iterations = 20;
  double function_tolerance = 1e-6;
  int num_threads = 1;
  // Windows waiting in WindowedBundleAdjuster's queue (odometry with the mapping thread); a new
  // one beyond this drops the oldest pending one (a newer window supersedes it).
  int max_queue = 2;
  // Scheduling priority of the worker thread: idle leaves the cores to tracking and mapping
  // whenever they want them (the BA then lags and more windows are dropped); normal competes.
  ThreadPriority worker_priority = ThreadPriority::kIdle;
  // Odometry: the current keyframe's depth-filter hypotheses are shifted by the optimised
  // points' corrections (DepthMapper::ApplyIdepthCorrections); false: poses only.
  bool depth_feedback = true;
  // ... and with depth_feedback, the current keyframe's other hypotheses re-expressed in its frame
  // as the BA moved it relative to the keyframe its map was propagated from (off: only the
  // optimised points change; docs/windowed_ba.md compares the two).
  bool warp_current_map = false;
  // ... and with depth_feedback, the current keyframe's other hypotheses (and tracking's
  // translation relative to it) scaled to the BA's scale: the median refined / submitted inverse
  // depth of its optimised points (off: the map keeps its own scale; docs/windowed_ba.md measures
  // both).
  bool scale_current_map = false;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("enabled", &enabled,
            "Run windowed photometric + line bundle adjustment over the newest keyframes "
            "beside tracking (default false).");
    v.Field("problem_builder", &problem_builder,
            "Registered windowed BA problem builder: windowed_ba (row-wise loss) or "
            "windowed_ba_ceres_loss (loss per residual block).");
    v.Field("window", &window, "Newest keyframes optimised (>= 2).");
    v.Field("max_points", &max_points, "Points per window (split over the keyframes).");
    v.Field("min_gradient", &min_gradient, "Smallest gradient magnitude of a selected point.");
    v.Choice("pattern", &pattern, WindowedBAPatternNames(),
             "Host pixels per point: single or dso8.");
    v.Field("min_targets", &min_targets, "Other keyframes a point must reproject into (>= 1).");
    v.Choice("newest_keyframe_points", &newest_keyframe_points, NewestKeyframePointsNames(),
             "Points of the newest keyframe (its map propagated from the previous one): host "
             "(with depth priors, default), host_no_prior, or target_only (as in DSO).");
    v.Choice("interpolation", &interpolation, ImageInterpolationNames(),
             "Sampling of the target images: bilinear or bicubic.");
    v.Choice("brightness", &brightness, BrightnessModelNames(),
             "Per-keyframe affine brightness estimated (affine) or held (none).");
    v.Field("brightness_prior_sigma_a", &brightness_prior_sigma_a,
            "Standard deviation of the prior on each keyframe's log-gain a.");
    v.Field("brightness_prior_sigma_b", &brightness_prior_sigma_b,
            "Standard deviation of the prior on each keyframe's bias b, gray levels.");
    v.Field("idepth_prior_scale", &idepth_prior_scale,
            "Prior on each inverse depth: N(input, (scale^2) V), V the depth filter's variance; "
            "0 = none.");
    v.Choice("idepth_prior_loss", &idepth_prior_loss, RobustLossKindNames(),
             "Robust loss on the inverse-depth priors: none (default), huber or cauchy.");
    v.Field("idepth_prior_loss_threshold", &idepth_prior_loss_threshold,
            "Threshold of idepth_prior_loss, in sigmas of the prior (default 2).");
    v.Field("depth_variance_in_weights", &depth_variance_in_weights,
            "Rows' weights carry the depth filter's variance (eqs. 5, 6 as in tracking); false "
            "(default): image noise and line covariance only, V in the depth prior alone.");
    v.Field("lines", &lines, "Point-to-line rows for points on edges with a line observation.");
    v.Field("outlier_energy_factor", &outlier_energy_factor,
            "A photometric target whose energy at the input exceeds this^2 times the window's "
            "median is left out; 0 = off (default 0).");
    v.Field("marginalize", &marginalize,
            "Marginalise the keyframe leaving a full window into a prior on the others' poses "
            "(DSO); false: fixed lag (default false).");
    v.Choice("leaving", &leaving, LeavingKeyframeNames(),
             "Keyframe leaving a full window: oldest (default) or spread (DSO: out of view of "
             "the newest first, else the distance score; not with marginalize).");
    v.Field("leaving_min_visible", &leaving_min_visible,
            "spread: a keyframe with less than this fraction of its points in view of the "
            "newest keyframe leaves first (default 0.05).");
    v.Field("baseline_prior_sigma_ratio", &baseline_prior_sigma_ratio,
            "sigma of the scale prior as a fraction of the baseline.");
    v.Section("weighting", &weighting, "Weighting of the residual families and robust loss.");
    v.Choice("solver", &solver, WindowedBASolverNames(), "ceres or gauss_newton.");
    v.Choice("linear_solver", &linear_solver, BALinearSolverNames(),
             "Ceres linear solver: sparse_schur, dense_schur, sparse_normal_cholesky.");
    v.Field("max_iterations", &max_iterations, "Iterations per window.");
    v.Field("function_tolerance", &function_tolerance, "Relative cost-change tolerance.");
    v.Field("num_threads", &num_threads, "Ceres threads per solve.");
    v.Field("max_queue", &max_queue,
            "Pending windows in the worker's queue (oldest dropped; default 2).");
    v.Choice("worker_priority", &worker_priority, ThreadPriorityNames(),
             "Worker thread: idle (default; runs on cores tracking and mapping leave), low "
             "(nice 19) or normal.");
    v.Field("depth_feedback", &depth_feedback,
            "Shift the current keyframe's depth-filter hypotheses by the optimised points' "
            "corrections (default true); false: poses only.");
    v.Field("warp_current_map", &warp_current_map,
            "depth_feedback: also re-express the current keyframe's other hypotheses in its "
            "frame as moved by the BA relative to its propagation source (default false).");
    v.Field("scale_current_map", &scale_current_map,
            "depth_feedback: also scale the current keyframe's other hypotheses and tracking's "
            "translation to the BA's scale (median refined / submitted inverse depth; default "
            "false).");
  }
  // "" when valid, otherwise what is wrong (names the key; an unknown problem_builder lists the
  // registered ones).
  std::string Check() const;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_OPTIONS_H_
