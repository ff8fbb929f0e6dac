#include "core/evaluation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <stdexcept>

#include "core/constant_velocity_start.h"

namespace pldvo {
namespace {

void RequireIncreasing(const Trajectory& trajectory, const char* name) {
  for (size_t i = 1; i < trajectory.size(); ++i) {
    if (!(trajectory[i].timestamp > trajectory[i - 1].timestamp)) {
      throw std::invalid_argument(std::string(name) + ": timestamps do not increase at pose " +
                                  std::to_string(i));
    }
  }
}

// The rotation angle of q in [0, pi] (either sign of the double cover).
double RotationAngle(const Eigen::Quaterniond& q) {
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

// The pose at time t: the pose stamped t (within 1 us), or the interpolation (translation linear,
// rotation slerp) between the poses just before and after t when they are at most max_gap apart.
bool InterpolatePose(const Trajectory& trajectory, double t, double max_gap, SE3* pose) {
  const auto it =
      std::lower_bound(trajectory.begin(), trajectory.end(), t,
                       [](const StampedPose& p, double value) { return p.timestamp < value; });
  constexpr double kSameTime = 1e-6;  // s: stamps that differ by the text round trip only
  if (it != trajectory.end() && it->timestamp - t <= kSameTime) {
    *pose = it->world_from_cam;
    return true;
  }
  if (it == trajectory.begin()) return false;
  if (t - (it - 1)->timestamp <= kSameTime) {
    *pose = (it - 1)->world_from_cam;
    return true;
  }
  if (it == trajectory.end()) return false;
  const StampedPose& before = *(it - 1);
  const StampedPose& after = *it;
  const double gap = after.timestamp - before.timestamp;
  if (gap > max_gap) return false;
  const double f = (t - before.timestamp) / gap;
  *pose =
      SE3(before.world_from_cam.rotation().slerp(f, after.world_from_cam.rotation()),
          (1.0 - f) * before.world_from_cam.translation() + f * after.world_from_cam.translation());
  return true;
}

int NearestPose(const Trajectory& trajectory, double t) {
  const auto it = std::lower_bound(
      trajectory.begin(), trajectory.end(), t,
      [](const StampedPose& pose, double value) { return pose.timestamp < value; });
  const int hi = static_cast<int>(it - trajectory.begin());
  int best = -1;
  double best_diff = std::numeric_limits<double>::infinity();
  for (int i : {hi - 1, hi}) {
    if (i < 0 || i >= static_cast<int>(trajectory.size())) continue;
    const double diff = std::abs(trajectory[i].timestamp - t);
    if (diff < best_diff) {
      best_diff = diff;
      best = i;
    }
  }
  return best;
}

}  // namespace

Sim3Alignment AlignUmeyama(const std::vector<Eigen::Vector3d>& src,
                           const std::vector<Eigen::Vector3d>& dst, bool with_scale) {
  if (src.size() != dst.size()) throw std::invalid_argument("AlignUmeyama: sizes differ");
  if (src.size() < 3) throw std::invalid_argument("AlignUmeyama: needs at least 3 point pairs");
  const Eigen::Index n = static_cast<Eigen::Index>(src.size());
  Eigen::Matrix<double, 3, Eigen::Dynamic> src_points(3, n), dst_points(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    src_points.col(i) = src[i];
    dst_points.col(i) = dst[i];
  }
  // Umeyama divides by sigma_src^2 (eq. 42), which is 0 when every source point is the same.
  Eigen::Vector3d mean_src = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& point : src) mean_src += point;
  mean_src /= static_cast<double>(n);
  double src_spread = 0.0;  // n sigma_src^2
  for (const Eigen::Vector3d& point : src) src_spread += (point - mean_src).squaredNorm();
  if (!(src_spread > 0.0)) {
    throw std::invalid_argument("AlignUmeyama: all source points coincide");
  }
  // Eqs. 39-42, with S = diag(1, 1, -1) when det(U) det(V) < 0 so that R is a proper rotation.
  // The SE(3) solution carries R alone; the Sim(3) one returns s R (the same R: the same SVD),
  // so s = tr(R^T s R) / 3, which stays defined when s = 0 (every dst point the same).
  const Eigen::Matrix4d rigid = Eigen::umeyama(src_points, dst_points, /*with_scaling=*/false);
  Sim3Alignment alignment;
  alignment.rotation = rigid.topLeftCorner<3, 3>();
  alignment.translation = rigid.topRightCorner<3, 1>();
  if (with_scale) {
    const Eigen::Matrix4d similarity = Eigen::umeyama(src_points, dst_points, true);
    alignment.scale =
        (alignment.rotation.transpose() * similarity.topLeftCorner<3, 3>()).trace() / 3.0;
    alignment.translation = similarity.topRightCorner<3, 1>();
  }
  return alignment;
}

std::string EvaluationOptions::Check() const {
  if (!(max_time_diff >= 0.0)) return "max_time_diff must be >= 0";
  if (!(rpe_delta > 0.0)) return "rpe_delta must be > 0";
  if (!(scale_window > 0.0)) return "scale_window must be > 0";
  if (!(constant_velocity_tolerance >= 0.0)) return "constant_velocity_tolerance must be >= 0";
  return "";
}

std::vector<std::pair<int, int>> AssociateByTimestamp(const Trajectory& estimate,
                                                      const Trajectory& ground_truth,
                                                      double max_time_diff) {
  std::vector<std::pair<int, int>> matches;
  for (int i = 0; i < static_cast<int>(estimate.size()); ++i) {
    const int k = NearestPose(ground_truth, estimate[i].timestamp);
    if (k >= 0 && std::abs(ground_truth[k].timestamp - estimate[i].timestamp) <= max_time_diff) {
      matches.emplace_back(i, k);
    }
  }
  return matches;
}

EvaluationResult EvaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                    const EvaluationOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw std::invalid_argument("evaluation options: " + problem);
  RequireIncreasing(ground_truth, "ground truth");
  RequireIncreasing(estimate, "estimate");
  const int constant_start =
      ConstantVelocityStartPoses(ground_truth, options.constant_velocity_tolerance);
  // A path that is one constant velocity throughout (a synthetic test) is evaluated whole.
  if (options.skip_constant_velocity_start && constant_start > 0 &&
      constant_start < static_cast<int>(ground_truth.size())) {
    // From the start's last pose on; the estimate's poses before it cannot be associated.
    const Trajectory measured(ground_truth.begin() + (constant_start - 1), ground_truth.end());
    Trajectory later;
    for (const StampedPose& pose : estimate) {
      if (pose.timestamp >= measured.front().timestamp - options.max_time_diff) {
        later.push_back(pose);
      }
    }
    EvaluationOptions all = options;
    all.skip_constant_velocity_start = false;
    EvaluationResult result = EvaluateTrajectory(measured, later, all);
    result.constant_velocity_start_poses = constant_start;
    result.skipped_ground_truth_poses = constant_start - 1;
    return result;
  }
  const std::vector<std::pair<int, int>> matches =
      AssociateByTimestamp(estimate, ground_truth, options.max_time_diff);
  if (matches.size() < 3) {
    throw std::invalid_argument("only " + std::to_string(matches.size()) + " of " +
                                std::to_string(estimate.size()) +
                                " estimate poses have a ground-truth pose within " +
                                std::to_string(options.max_time_diff) + " s (need 3)");
  }
  EvaluationResult result;
  result.num_associated = static_cast<int>(matches.size());
  result.constant_velocity_start_poses = constant_start;

  // ATE after Sim(3) alignment of the estimate's positions onto the ground truth's.
  std::vector<Eigen::Vector3d> est_positions, gt_positions;
  for (const auto& [i, k] : matches) {
    est_positions.push_back(estimate[i].world_from_cam.translation());
    gt_positions.push_back(ground_truth[k].world_from_cam.translation());
  }
  result.gt_from_est = AlignUmeyama(est_positions, gt_positions, options.align_scale);
  result.scale = result.gt_from_est.scale;
  double squared_sum = 0.0;
  for (size_t m = 0; m < matches.size(); ++m) {
    squared_sum += (gt_positions[m] - result.gt_from_est * est_positions[m]).squaredNorm();
  }
  result.ate_m = std::sqrt(squared_sum / matches.size());

  // The estimate's frame interval: the median time between consecutive estimate poses (robust
  // to dropped frames as long as fewer than half the intervals are gaps).
  std::vector<double> intervals;
  for (size_t i = 1; i < estimate.size(); ++i) {
    intervals.push_back(estimate[i].timestamp - estimate[i - 1].timestamp);
  }
  const double frame_interval = Median(intervals);

  // RPE: for each associated estimate pose i, the estimate pose j nearest to t_i + delta; both
  // associated (Sturm et al. 2012, eq. 1 with Delta = rpe_delta). E = (gt_i^-1 gt_j)^-1 (est_i^-1
  // est_j) with the estimate's relative translation scaled by s; errors divided by the pair's
  // interval t_j - t_i (per second).
  std::vector<int> gt_of_estimate(estimate.size(), -1);
  for (const auto& [i, k] : matches) gt_of_estimate[i] = k;
  double trans_squared = 0.0, rot_squared = 0.0, still_squared = 0.0;
  for (const auto& [i, k] : matches) {
    const int j = NearestPose(estimate, estimate[i].timestamp + options.rpe_delta);
    if (j <= i || gt_of_estimate[j] < 0) continue;
    const double interval = estimate[j].timestamp - estimate[i].timestamp;
    // The pose nearest to t_i + delta is at most half a frame off unless frames are missing
    // there; then the pair is skipped (the loss shows in the coverage).
    if (std::abs(interval - options.rpe_delta) > 0.5 * frame_interval * (1.0 + 1e-9)) continue;
    const SE3 gt_j_from_i =
        ground_truth[k].world_from_cam.Inverse() * ground_truth[gt_of_estimate[j]].world_from_cam;
    const SE3 est_relative = estimate[i].world_from_cam.Inverse() * estimate[j].world_from_cam;
    const SE3 est_j_from_i(est_relative.rotation(), result.scale * est_relative.translation());
    const SE3 error = gt_j_from_i.Inverse() * est_j_from_i;
    const double trans_per_s = error.translation().norm() / interval;
    const double rot_per_s = RotationAngle(error.rotation()) / interval;
    trans_squared += trans_per_s * trans_per_s;
    // A still estimate (R, 0): the error's translation is -R_gt^T t_gt, of length |t_gt|.
    const double still_per_s = gt_j_from_i.translation().norm() / interval;
    still_squared += still_per_s * still_per_s;
    rot_squared += rot_per_s * rot_per_s;
    ++result.num_pairs;
  }
  if (result.num_pairs > 0) {
    result.rpe_cm_s = 100.0 * std::sqrt(trans_squared / result.num_pairs);
    result.rpe_deg_s = 180.0 / M_PI * std::sqrt(rot_squared / result.num_pairs);
    result.rpe_cm_s_still = 100.0 * std::sqrt(still_squared / result.num_pairs);
  } else {
    result.rpe_cm_s = std::numeric_limits<double>::quiet_NaN();
    result.rpe_deg_s = std::numeric_limits<double>::quiet_NaN();
    result.rpe_cm_s_still = std::numeric_limits<double>::quiet_NaN();
  }

  // Scale per window: path lengths over the steps between consecutive associated poses.
  const double start = estimate[matches.front().first].timestamp;
  std::vector<double> est_length, gt_length;
  for (size_t m = 1; m < matches.size(); ++m) {
    const double t = estimate[matches[m - 1].first].timestamp;
    const size_t window = static_cast<size_t>((t - start) / options.scale_window);
    if (window >= est_length.size()) {
      est_length.resize(window + 1, 0.0);
      gt_length.resize(window + 1, 0.0);
    }
    est_length[window] += (est_positions[m] - est_positions[m - 1]).norm();
    gt_length[window] += (gt_positions[m] - gt_positions[m - 1]).norm();
  }
  for (size_t w = 0; w < est_length.size(); ++w) {
    if (gt_length[w] > 0.0) result.window_scales.push_back(est_length[w] / gt_length[w]);
  }
  if (!result.window_scales.empty()) {
    const auto [lowest, highest] =
        std::minmax_element(result.window_scales.begin(), result.window_scales.end());
    result.scale_drift =
        *lowest > 0.0 ? *highest / *lowest : std::numeric_limits<double>::infinity();
  }

  // Coverage: associated poses times the estimate's frame interval over the ground-truth span.
  const double gt_span = ground_truth.back().timestamp - ground_truth.front().timestamp;
  result.coverage =
      std::min(1.0, result.num_associated * frame_interval / (gt_span + frame_interval));
  return result;
}

std::vector<FrameMotionError> EvaluateFrameMotion(const Trajectory& ground_truth,
                                                  const Trajectory& estimate, double scale,
                                                  double max_time_diff) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw std::invalid_argument("EvaluateFrameMotion: scale must be positive and finite");
  }
  RequireIncreasing(ground_truth, "ground truth");
  RequireIncreasing(estimate, "estimate");
  // The ground truth at each estimate pose's timestamp (interpolated, see InterpolatePose).
  std::vector<SE3> gt_at(estimate.size());
  std::vector<char> have(estimate.size(), 0);
  for (size_t i = 0; i < estimate.size(); ++i) {
    have[i] = InterpolatePose(ground_truth, estimate[i].timestamp, 2.0 * max_time_diff, &gt_at[i]);
  }
  constexpr double kDegPerRad = 180.0 / M_PI;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::vector<FrameMotionError> errors;
  for (size_t b = 1; b < estimate.size(); ++b) {
    const size_t a = b - 1;
    if (!have[a] || !have[b]) continue;
    const SE3 gt_motion = gt_at[a].Inverse() * gt_at[b];
    const SE3 est_motion = estimate[a].world_from_cam.Inverse() * estimate[b].world_from_cam;
    FrameMotionError error;
    error.timestamp = estimate[b].timestamp;
    error.rotation_error_deg =
        kDegPerRad * RotationAngle(gt_motion.rotation().conjugate() * est_motion.rotation());
    const double gt_length = gt_motion.translation().norm();
    const double est_length = est_motion.translation().norm();
    error.translation_direction_error_deg =
        gt_length > 0.0 && est_length > 0.0
            ? kDegPerRad *
                  std::atan2(gt_motion.translation().cross(est_motion.translation()).norm(),
                             gt_motion.translation().dot(est_motion.translation()))
            : kNaN;
    error.translation_ratio = gt_length > 0.0 ? scale * est_length / gt_length : kNaN;
    const Eigen::Vector3d gt_rotation = LogSO3(gt_motion.rotation_matrix());
    const Eigen::Vector3d est_rotation = LogSO3(est_motion.rotation_matrix());
    error.true_rotation_deg = kDegPerRad * gt_rotation.norm();
    error.rotation_along_true_deg =
        gt_rotation.norm() > 0.0 ? kDegPerRad * est_rotation.dot(gt_rotation.normalized()) : 0.0;
    errors.push_back(error);
  }
  return errors;
}

void WriteFrameMotionErrorsCsv(const std::vector<FrameMotionError>& errors, std::ostream& out) {
  const auto number = [&out](double value) -> std::ostream& {
    return std::isnan(value) ? out << "nan" : out << value;
  };
  out << "timestamp,rotation_error_deg,translation_direction_error_deg,translation_ratio,"
         "true_rotation_deg,rotation_along_true_deg\n";
  out << std::setprecision(9);
  for (const FrameMotionError& error : errors) {
    out << error.timestamp << ",";
    number(error.rotation_error_deg) << ",";
    number(error.translation_direction_error_deg) << ",";
    number(error.translation_ratio) << ",";
    number(error.true_rotation_deg) << ",";
    number(error.rotation_along_true_deg) << "\n";
  }
}

double PooledRotationRatio(const std::vector<FrameMotionError>& errors) {
  double along = 0.0, truth = 0.0;
  for (const FrameMotionError& error : errors) {
    along += error.rotation_along_true_deg;
    truth += error.true_rotation_deg;
  }
  return truth > 0.0 ? along / truth : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace pldvo
