// ceres::Solve on LeastSquaresProblem::ToCeresProblem(): trust-region Levenberg-Marquardt with
// a dense linear solver (the pose has 6 tangent dimensions), tolerances and threads from
// SolverOptions, silent logging. An iteration callback is forwarded through a
// ceres::IterationCallback with update_state_every_iteration so that the parameter blocks hold
// the current estimate when it runs.
#ifndef PLDVO_BACKEND_OPTIMIZATION_CERES_SOLVER_H_
#define PLDVO_BACKEND_OPTIMIZATION_CERES_SOLVER_H_

#include <ceres/solver.h>

#include "backend/optimization/solver.h"

namespace pldvo {

// Our summary of a ceres::Solve (iterations without Ceres' iteration 0, the initial state).
SolverSummary SummarizeCeresSolve(const ceres::Solver::Summary& summary);

class CeresSolver : public Solver {
 public:
  explicit CeresSolver(const SolverOptions& options) : options_(options) {}
  SolverSummary Solve(LeastSquaresProblem* problem,
                      const SolverIterationCallback& callback = nullptr) const override;

 private:
  SolverOptions options_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_CERES_SOLVER_H_
