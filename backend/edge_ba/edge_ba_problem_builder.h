// EdgeBAProblemBuilder: the least-squares problem of one window of edge bundle adjustment
// (docs/edge_ba.md).
//
// Variables: the cam_from_world pose of each of the newest EdgeBAOptions::window keyframes
// (double[7], SE3Manifold) and each usable 3D line (double[6] = [o, d], ceres::LineManifold<3>,
// 4 DOF). Residuals: one LineObservationResidual block per (keyframe, line) observation, one
// row per used edge pixel, sqrt_info from the covariance model at the linearisation point
// (the input estimates), robust loss row-wise inside the cost function.
//
// Gauge (7 DOF): the oldest pose constant; scale by a BaselinePriorResidual between the oldest
// keyframe and the next one (or, if that baseline is below 1e-3 of the largest baseline from the
// oldest keyframe, the farthest one), or by holding the two oldest poses constant.
// A keyframe observing fewer than 3 usable lines is held constant (its pose would be
// unconstrained or nearly so). Line selection: see EdgeBALineStatus and EdgeBAOptions.
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_PROBLEM_BUILDER_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_PROBLEM_BUILDER_H_

#include <array>
#include <vector>

#include "backend/edge_ba/edge_ba_options.h"
#include "backend/edge_ba/edge_ba_window.h"
#include "backend/optimization/least_squares_problem.h"

namespace pldvo {

// The problem with the parameter arrays it points into. Movable (the arrays live in vectors
// whose buffers move along), not copyable.
struct EdgeBAProblem {
  // Window keyframes, oldest first: index into EdgeBAWindow::keyframes, parameters, constness.
  std::vector<int> keyframe_indices;
  std::vector<std::array<double, 7>> poses;  // cam_from_world
  std::vector<bool> pose_fixed;
  // Every line of the window (listed or observed), sorted by id.
  std::vector<int> line_ids;
  std::vector<std::array<double, 6>> lines;  // [o, d], |d| = 1
  std::vector<EdgeBALineStatus> line_status;
  LeastSquaresProblem problem;
  // Pose-pose prior of the scale gauge: window positions of the two keyframes, or -1.
  int baseline_keyframe_a = -1;
  int baseline_keyframe_b = -1;
  double baseline = 0.0;
  int num_pixel_residuals = 0;
  int num_motion_priors = 0;  // EdgeBAMotionPrior blocks

  // Blocks that the solver varies (lines first, for the Schur ordering).
  std::vector<double*> VariableLineBlocks();
  std::vector<double*> VariablePoseBlocks();
  int NumVariableTangentParameters() const;
};

class EdgeBAProblemBuilder {
 public:
  // Throws std::invalid_argument when the options are invalid.
  explicit EdgeBAProblemBuilder(const EdgeBAOptions& options);
  // Throws std::invalid_argument on a malformed window (CheckEdgeBAWindow).
  EdgeBAProblem Build(const EdgeBAWindow& window) const;

 private:
  EdgeBAOptions options_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_PROBLEM_BUILDER_H_
