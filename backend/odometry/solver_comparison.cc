#include "backend/odometry/solver_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include "core/evaluation.h"
#include "core/statistics.h"

namespace pldvo {
namespace {

double Max(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

}  // namespace

SolverComparison::SolverComparison(const std::string& path, const std::string& solver_name)
    : file_(path), solver_name_(solver_name) {
  file_ << "# pldvo run, odometry.compare_solver=" << solver_name
        << ": timestamp tx ty tz qx qy qz qw (world_from_cam)\n";
  file_.flush();
}

bool SolverComparison::Add(const OdometryFrameResult& result) {
  if (!IsTracked(result.status)) return true;
  const SE3& pose = result.compared ? result.world_from_cam_compared : result.world_from_cam;
  if (result.compared) {
    // Against the pose the run reports (for a new keyframe after a synchronous edge BA, the
    // refined one).
    const SE3 difference = result.world_from_cam.Inverse() * result.world_from_cam_compared;
    FrameDifference d;
    d.frame = result.index;
    d.translation_m = difference.translation().norm();
    d.rotation_deg = 180.0 / M_PI * Eigen::AngleAxisd(difference.rotation()).angle();
    if (!result.tracking.levels.empty()) d.run_cost = result.tracking.levels.back().final_cost;
    d.compared_cost = result.compared_final_cost;
    d.run_valid_rows = result.tracking.valid_residuals;
    d.compared_valid_rows = result.compared_valid_residuals;
    differences_.push_back(d);
    run_tracking_ms_.push_back(result.tracking.ms);
    compare_tracking_ms_.push_back(result.timing.compare_tracking_ms);
    lost_ += result.compared_status == TrackingStatus::kLost;
  }
  return AddUncompared({result.timestamp, pose});
}

bool SolverComparison::AddUncompared(const StampedPose& pose) {
  trajectory_.push_back(pose);
  WriteTumLine(trajectory_.back(), file_);
  return static_cast<bool>(file_.flush());
}

nlohmann::json SolverComparison::Summary(const Trajectory* ground_truth,
                                         const EvaluationOptions& evaluation) const {
  nlohmann::json summary;
  summary["solver"] = solver_name_;
  std::vector<double> translation_m, rotation_deg;
  for (const FrameDifference& d : differences_) {
    translation_m.push_back(d.translation_m);
    rotation_deg.push_back(d.rotation_deg);
  }
  summary["frames_compared"] = differences_.size();
  summary["frames_lost"] = lost_;
  summary["translation_diff_m_median"] = Median(translation_m);
  summary["translation_diff_m_max"] = Max(translation_m);
  summary["rotation_diff_deg_median"] = Median(rotation_deg);
  summary["rotation_diff_deg_max"] = Max(rotation_deg);
  std::vector<FrameDifference> largest = differences_;
  const size_t count = std::min<size_t>(kLargestDifferences, largest.size());
  std::partial_sort(largest.begin(), largest.begin() + count, largest.end(),
                    [](const FrameDifference& a, const FrameDifference& b) {
                      return a.translation_m > b.translation_m;
                    });
  summary["largest_differences"] = nlohmann::json::array();
  for (size_t i = 0; i < count; ++i) {
    const FrameDifference& d = largest[i];
    summary["largest_differences"].push_back({{"frame", d.frame},
                                              {"translation_m", d.translation_m},
                                              {"rotation_deg", d.rotation_deg},
                                              {"run_cost", d.run_cost},
                                              {"compared_cost", d.compared_cost},
                                              {"run_valid_rows", d.run_valid_rows},
                                              {"compared_valid_rows", d.compared_valid_rows}});
  }
  summary["tracking_ms_median"] = Median(compare_tracking_ms_);
  summary["run_tracking_ms_median"] = Median(run_tracking_ms_);
  if (ground_truth != nullptr && !ground_truth->empty()) {
    try {
      const EvaluationResult eval = EvaluateTrajectory(*ground_truth, trajectory_, evaluation);
      summary["rpe_cm_s"] = std::isfinite(eval.rpe_cm_s) ? nlohmann::json(eval.rpe_cm_s) : nullptr;
      summary["rpe_deg_s"] =
          std::isfinite(eval.rpe_deg_s) ? nlohmann::json(eval.rpe_deg_s) : nullptr;
      summary["ate_m"] = eval.ate_m;
    } catch (const std::exception& e) {
      summary["evaluation_error"] = e.what();
    }
  }
  return summary;
}

std::string SolverComparison::Line(const nlohmann::json& s) const {
  char line[512];
  std::snprintf(line, sizeof(line),
                "compare %s on the same problems: %d frames (%d lost), pose difference median "
                "%.2e m / %.2e deg, max %.2e m / %.2e deg; tracking median %.2f ms (run %.2f ms)",
                solver_name_.c_str(), s["frames_compared"].get<int>(), lost_,
                s["translation_diff_m_median"].get<double>(),
                s["rotation_diff_deg_median"].get<double>(),
                s["translation_diff_m_max"].get<double>(), s["rotation_diff_deg_max"].get<double>(),
                s["tracking_ms_median"].get<double>(), s["run_tracking_ms_median"].get<double>());
  std::string text = line;
  if (!s["largest_differences"].empty()) {
    const nlohmann::json& largest = s["largest_differences"][0];
    std::snprintf(line, sizeof(line), "; largest at frame %d (final cost: run %.6g, %s %.6g)",
                  largest["frame"].get<int>(), largest["run_cost"].get<double>(),
                  solver_name_.c_str(), largest["compared_cost"].get<double>());
    text += line;
  }
  if (s.contains("rpe_cm_s") && s["rpe_cm_s"].is_number()) {
    std::snprintf(line, sizeof(line), "; RPE %.3f cm/s, ATE %.4f m", s["rpe_cm_s"].get<double>(),
                  s["ate_m"].get<double>());
    text += line;
  }
  return text;
}

}  // namespace pldvo
