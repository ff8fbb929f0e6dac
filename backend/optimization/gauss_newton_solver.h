// Hand-written Gauss-Newton on a LeastSquaresProblem (the seed paper's Sec. IV update, which the
// paper does not number; its eq. 5 is the photometric variance Sigma_f):
//
//   delta_xi = -(J^T W J)^-1 J^T W E,   x <- Plus(x, delta_xi),
//
// where E stacks the residuals and J their Jacobians in the tangent space. W needs no separate
// handling: the cost functions already whiten each row with its sqrt_info (so J^T W J is the
// J^T J of the whitened residuals), and robust weights computed row-wise inside the cost
// functions' square-root form come out of Evaluate the same way. A residual block that carries
// a ceres::LossFunction (e.g. one block per pixel) is corrected exactly as Ceres does (Triggs et
// al., "Bundle adjustment - a modern synthesis", sec. 4.3): with s = |r|^2 and rho', rho'',
//   alpha = 1 - sqrt(1 + 2 s rho''/rho'),  r~ = sqrt(rho') / (1 - alpha) r,
//   J~ = sqrt(rho') (I - alpha r r^T / s) J,
// (alpha = 0, i.e. IRLS with weight rho', when rho'' <= 0), so that J~^T r~ = rho' J^T r is
// the exact gradient of 1/2 rho(s) and both solvers minimise the same objective.
//
// Tangent-space Jacobians are the cost functions' ambient Jacobians times
// Manifold::PlusJacobian(x). The normal equations are dense (intended for small problems such
// as a 6-DOF pose); accumulation uses buffers sized once per solve, no per-residual allocation.
// Blocks marked eliminated (LeastSquaresProblem::SetParameterBlockEliminated: 1-D blocks no two
// of which share a residual block, such as the inverse depths of bundle adjustment) are removed
// by the Schur complement S = H_KK - H_KP H_PP^-1 H_PK before the LDLT, which then factorises
// only the kept (pose, brightness) part; the step is the dense one, to rounding.
// Step acceptance and stopping: see SolverOptions. A trial step after an accepted one is
// linearised in full, so a run of accepted steps evaluates the cost functions once per step
// (Ceres' LM: twice, cost then Jacobians); after a rejection only the cost is evaluated.
#ifndef PLDVO_BACKEND_OPTIMIZATION_GAUSS_NEWTON_SOLVER_H_
#define PLDVO_BACKEND_OPTIMIZATION_GAUSS_NEWTON_SOLVER_H_

#include "backend/optimization/solver.h"

namespace pldvo {

class GaussNewtonSolver : public Solver {
 public:
  explicit GaussNewtonSolver(const SolverOptions& options) : options_(options) {}
  SolverSummary Solve(LeastSquaresProblem* problem,
                      const SolverIterationCallback& callback = nullptr) const override;

 private:
  SolverOptions options_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_GAUSS_NEWTON_SOLVER_H_
