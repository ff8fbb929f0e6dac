// Trajectory evaluation as the TUM RGB-D benchmark defines it (Sturm et al., IROS 2012), for a
// monocular estimate whose scale is unknown: association by timestamp, Umeyama Sim(3) alignment,
// absolute trajectory error (ATE), relative pose error (RPE) per second, and coverage.
// Definitions and units: docs/evaluation.md.
#ifndef PLDVO_CORE_EVALUATION_H_
#define PLDVO_CORE_EVALUATION_H_

#include <Eigen/Core>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

// Median and Mean: core/statistics.h (included here for the callers that long found them here).
#include "core/statistics.h"
#include "core/trajectory_io.h"

namespace pldvo {

// p_dst = scale * rotation * p_src + translation.
struct Sim3Alignment {
  double scale = 1.0;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator*(const Eigen::Vector3d& p_src) const {
    return scale * (rotation * p_src) + translation;
  }
};

// The closed-form least-squares similarity (Umeyama, PAMI 1991, eqs. 40-42) minimising
// sum_i |dst_i - (s R src_i + t)|^2; with_scale = false fixes s = 1 (SE(3) alignment).
// Throws std::invalid_argument for fewer than 3 pairs, different sizes, or all src points equal.
Sim3Alignment AlignUmeyama(const std::vector<Eigen::Vector3d>& src,
                           const std::vector<Eigen::Vector3d>& dst, bool with_scale = true);

struct EvaluationOptions {
  // Largest |t_est - t_gt| for an estimate pose to be associated with its nearest ground-truth
  // pose, in seconds (TUM associate.py's default).
  double max_time_diff = 0.02;
  // RPE interval in seconds: the TUM benchmark's drift per second.
  double rpe_delta = 1.0;
  // Sim(3) alignment (monocular, scale unknown); false aligns with SE(3) and reports scale 1.
  bool align_scale = true;
  // Length of the windows of the scale drift (window_scales), seconds.
  double scale_window = 1.0;
  // Ground truth that starts at one constant velocity (core/constant_velocity_start.h): the
  // relative change of consecutive velocities up to which they count as one, and whether to
  // evaluate from the last pose of such a start only (false: every pose, as the TUM and KITTI
  // tools do; the start is reported either way; a path at one velocity throughout is evaluated
  // whole).
  double constant_velocity_tolerance = 1e-4;
  bool skip_constant_velocity_start = false;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("max_time_diff", &max_time_diff,
            "Largest timestamp difference (s) to associate an estimate pose with ground truth.");
    v.Field("rpe_delta", &rpe_delta, "RPE interval in seconds (errors are reported per second).");
    v.Field("align_scale", &align_scale,
            "Align with Sim(3) (true, monocular) or SE(3) (false) before ATE and RPE.");
    v.Field("scale_window", &scale_window,
            "Window (s) of the local scale: estimated over ground-truth path length.");
    v.Field("constant_velocity_tolerance", &constant_velocity_tolerance,
            "Consecutive ground-truth velocities differing by at most this fraction of the speed "
            "are one constant velocity (an extrapolated start; default 1e-4).");
    v.Field("skip_constant_velocity_start", &skip_constant_velocity_start,
            "Evaluate from the last pose of a ground-truth start of >= 5 constant-velocity steps "
            "(e.g. KITTI 00's first 14 poses; default false: every pose).");
  }
  // "" when valid, otherwise what is wrong.
  std::string Check() const;
};

struct EvaluationResult {
  // RMSE of the associated positions after alignment, in metres of the ground truth.
  double ate_m = 0.0;
  // RMSE over pose pairs rpe_delta apart of the relative translational error per second (cm/s,
  // the estimate scaled by the alignment's scale) and of the relative rotation angle per second
  // (deg/s). NaN when no pair exists (estimate shorter than rpe_delta).
  double rpe_cm_s = 0.0;
  double rpe_deg_s = 0.0;
  // rpe_cm_s of an estimate that never moves, over the same pairs: the RMS of the ground truth's
  // own translation per second (cm/s; NaN without pairs). A translational RPE near it says the
  // translation was not tracked.
  double rpe_cm_s_still = 0.0;
  // The alignment's scale: ground-truth metres per estimate unit.
  double scale = 1.0;
  // Fraction of the ground-truth time span covered by associated estimate poses, in [0, 1]:
  // num_associated * dt / (gt_span + dt), dt the median interval between estimate poses.
  double coverage = 0.0;
  // Scale drift of a monocular estimate: per window of scale_window seconds (by the time of a
  // step's first pose), the estimate's path length over the ground truth's, both summed over the
  // steps between consecutive associated poses (estimate units per metre; 1 / scale where the
  // scale is that of the alignment). Windows in which the ground truth does not move are left
  // out. scale_drift = max / min of window_scales (1: no drift; 0 without windows).
  std::vector<double> window_scales;
  double scale_drift = 0.0;
  int num_pairs = 0;       // RPE pairs
  int num_associated = 0;  // estimate poses associated with ground truth
  Sim3Alignment gt_from_est;
  // Leading ground-truth poses at one constant velocity (0: none of >= 5 steps) and how many of
  // them were left out (skip_constant_velocity_start: all but the last).
  int constant_velocity_start_poses = 0;
  int skipped_ground_truth_poses = 0;
};

// (estimate index, ground-truth index) pairs: each estimate pose with the nearest ground-truth
// pose within max_time_diff. Both trajectories must have increasing timestamps.
std::vector<std::pair<int, int>> AssociateByTimestamp(const Trajectory& estimate,
                                                      const Trajectory& ground_truth,
                                                      double max_time_diff);

// Throws std::invalid_argument when fewer than 3 estimate poses can be associated, the
// timestamps do not increase, or the options are invalid.
EvaluationResult EvaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                    const EvaluationOptions& options = {});

// The error of one frame-to-frame motion, between consecutive estimate poses a and b
// (docs/evaluation.md, "Per-frame motion errors"). Both motions are a_from_b, in camera a.
struct FrameMotionError {
  double timestamp = 0.0;           // of pose b
  double rotation_error_deg = 0.0;  // angle of R_gt^T R_est
  // Angle between the estimated and the true translation; NaN when either is zero. Where the
  // rotation error tracks this angle, the rotation absorbs the translation (bas-relief ambiguity).
  double translation_direction_error_deg = 0.0;
  // scale |t_est| / |t_gt| (1: the motion's length agrees at the alignment's scale); NaN when the
  // ground truth does not move.
  double translation_ratio = 0.0;
  double true_rotation_deg = 0.0;  // angle of R_gt
  // The estimated rotation vector log(R_est) along the true axis log(R_gt) / |log(R_gt)|, deg (0
  // when the ground truth does not turn): over the true angle, how much of the turn is tracked.
  double rotation_along_true_deg = 0.0;
};

// sum rotation_along_true_deg / sum true_rotation_deg over `errors`: the estimate's turns over
// the true ones (1: no over- or under-rotation); NaN when the ground truth does not turn.
double PooledRotationRatio(const std::vector<FrameMotionError>& errors);

// One entry per pair of consecutive estimate poses that both have a ground-truth pose: the one
// stamped with the same time, or the interpolation between the two around it when they are at
// most 2 max_time_diff apart (a 30 Hz camera against 100 Hz motion capture: the nearest pose
// would be up to 5 ms off, a rotation error of its own on a fast turn). `scale` is ground-truth
// metres per estimate unit (the alignment's, EvaluationResult::scale). Throws std::invalid_argument
// when the timestamps do not increase or scale is not positive and finite.
std::vector<FrameMotionError> EvaluateFrameMotion(const Trajectory& ground_truth,
                                                  const Trajectory& estimate, double scale,
                                                  double max_time_diff);

// CSV with the header `timestamp,rotation_error_deg,translation_direction_error_deg,
// translation_ratio` ("nan" for NaN).
void WriteFrameMotionErrorsCsv(const std::vector<FrameMotionError>& errors, std::ostream& out);

}  // namespace pldvo

#endif  // PLDVO_CORE_EVALUATION_H_
