#include "backend/windowed_ba/marginalization.h"

#include <utility>
#include <vector>

#include "backend/optimization/normal_equations.h"
#include "residuals/se3_manifold.h"

namespace pldvo {

bool MarginalizeOldestKeyframe(const std::vector<int>& keyframe_ids, WindowedBAProblem* problem,
                               WindowedBAPrior* prior) {
  const int n = static_cast<int>(problem->poses.size());
  if (n < 2 || static_cast<int>(keyframe_ids.size()) != n) return false;
  LeastSquaresProblem& least_squares = problem->problem;
  for (int k = 0; k < n; ++k) {
    least_squares.SetParameterBlockVariable(problem->poses[k].data());
    least_squares.SetParameterBlockConstant(problem->brightness[k].data());
  }
  for (size_t i = 0; i < problem->points.size(); ++i) {
    if (problem->points[i].host == 0) {
      least_squares.SetParameterBlockVariable(&problem->idepths[i]);
    } else {
      least_squares.SetParameterBlockConstant(&problem->idepths[i]);
    }
  }
  std::vector<int> blocks = problem->oldest_host_blocks;
  if (problem->prior_block >= 0) blocks.push_back(problem->prior_block);
  NormalEquations normal_equations(least_squares);
  double cost = 0.0;
  if (!normal_equations.LinearizeBlocks(&blocks, &cost)) return false;

  // Keep the tangent columns of poses 1..n-1; eliminate the oldest pose and the inverse depths.
  std::vector<bool> keep(normal_equations.dimension(), false);
  for (int k = 1; k < n; ++k) {
    const int offset =
        normal_equations.TangentOffset(least_squares.ParameterBlockIndex(problem->poses[k].data()));
    for (int c = 0; c < kPoseTangentSize; ++c) keep[offset + c] = true;
  }
  WindowedBAPrior out;
  out.marginalized_through_id = keyframe_ids[0];
  for (int k = 1; k < n; ++k) {
    out.keyframe_ids.push_back(keyframe_ids[k]);
    out.cam_from_world.push_back(PoseFromParameters(problem->poses[k].data()));
  }
  // The kept columns come in the order the poses were added (oldest first), as the prior's.
  SchurComplement(normal_equations.hessian(), normal_equations.gradient(), keep, &out.information,
                  &out.gradient);
  *prior = std::move(out);
  return true;
}

}  // namespace pldvo
