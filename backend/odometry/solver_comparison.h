// The solver comparison of `pldvo run` (odometry.compare_solver, docs/tracking.md): collects, for
// every tracked frame, the run's pose and the pose the other solver found on the same final
// tracking problem, writes the other solver's trajectory as it goes, and summarises the
// difference (per-frame pose differences, RPE / ATE of both against ground truth, tracking time
// of both).
#ifndef PLDVO_BACKEND_ODOMETRY_SOLVER_COMPARISON_H_
#define PLDVO_BACKEND_ODOMETRY_SOLVER_COMPARISON_H_

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "backend/odometry/odometry_observer.h"
#include "core/evaluation.h"
#include "core/trajectory_io.h"

namespace pldvo {

class SolverComparison {
 public:
  // Opens `path` for the compared trajectory (TUM format); ok() tells whether it could.
  SolverComparison(const std::string& path, const std::string& solver_name);
  bool ok() const { return static_cast<bool>(file_); }

  // A frame of the run. Tracked frames go into the compared trajectory: with the compared pose
  // when the frame was compared, else with the run's pose (the first frame, re-initialisations).
  // False when the write failed.
  bool Add(const OdometryFrameResult& result);
  // A tracked frame the other solver did not see (before a re-anchored two-view start,
  // backward_start.h): the run's pose, as for the first frame. False when the write failed.
  bool AddUncompared(const StampedPose& pose);

  // The summary.json object: solver, frames compared, frames the other solver lost, median and
  // max translation (m) and rotation (deg) differences, median ms of one tracking solve (the
  // final one; the run's tracking_ms also holds alternative guesses and re-tracking), and
  // with ground truth rpe_cm_s / rpe_deg_s / ate_m of the compared trajectory (evaluated with
  // `evaluation`, the run's options).
  // `largest_differences`: the kLargestDifferences frames with the largest translation
  // difference, largest first, each with both solvers' final cost and valid rows at the finest
  // level (whether one solver stopped short or the two found different minima).
  nlohmann::json Summary(const Trajectory* ground_truth,
                         const EvaluationOptions& evaluation = {}) const;
  static constexpr int kLargestDifferences = 5;
  // One line for the run's final table.
  std::string Line(const nlohmann::json& summary) const;

 private:
  std::ofstream file_;
  std::string solver_name_;
  Trajectory trajectory_;
  struct FrameDifference {
    int frame = 0;
    double translation_m = 0.0;
    double rotation_deg = 0.0;
    double run_cost = 0.0;
    double compared_cost = 0.0;
    int run_valid_rows = 0;
    int compared_valid_rows = 0;
  };
  std::vector<FrameDifference> differences_;
  std::vector<double> run_tracking_ms_, compare_tracking_ms_;
  int lost_ = 0;  // compared frames the other solver reported lost
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_SOLVER_COMPARISON_H_
