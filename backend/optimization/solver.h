// One interface over the two solvers of a LeastSquaresProblem (config `tracking.solver`):
//   ceres         ceres::Solve with Levenberg-Marquardt on ToCeresProblem();
//   gauss_newton  the hand-written Gauss-Newton of gauss_newton_solver.h (the paper's Sec. IV
//                 update with LM-style damping as the step acceptance rule).
// Both evaluate the same CostFunction objects and update through the same Manifold::Plus, and
// both use the same three stopping tolerances with Ceres' definitions:
//   function:  |cost_old - cost_new| / cost_old <= function_tolerance (after an accepted step);
//   gradient:  max_i |g_i| <= gradient_tolerance (g = J^T r in the tangent space; Ceres measures
//              |x - Plus(x, -g)|_inf, equal to first order);
//   parameter: |delta| <= parameter_tolerance (|x| + parameter_tolerance).
// Gauss-Newton also stops (converged) when the decrease its linearised model predicts for the
// next step, -(g^T delta + delta^T H delta / 2), is below function_tolerance * cost: this
// avoids a cascade of rejected, ever more damped steps where the Jacobian is only approximate
// (photometric residuals with interpolated image gradients).
#ifndef PLDVO_BACKEND_OPTIMIZATION_SOLVER_H_
#define PLDVO_BACKEND_OPTIMIZATION_SOLVER_H_

#include <functional>
#include <memory>
#include <string>

#include "backend/optimization/least_squares_problem.h"
#include "core/options.h"

namespace pldvo {

struct SolverOptions {
  enum class Type { kCeres, kGaussNewton };
  enum class CeresLinearSolver { kDenseQr, kDenseNormalCholesky };

  Type type = Type::kGaussNewton;
  int max_iterations = 20;
  // 1e-5: the photometric cost's floor under its approximate Jacobian is ~1e-4 relative, so
  // tighter values mostly add rejected steps (docs/tracking.md, "Stopping criteria").
  double function_tolerance = 1e-5;
  double gradient_tolerance = 1e-10;
  double parameter_tolerance = 1e-8;
  // Ceres only. DENSE_NORMAL_CHOLESKY forms the 6x6 J^T J directly and measured faster than
  // DENSE_QR for tracking (docs/tracking.md, "Timing").
  CeresLinearSolver ceres_linear_solver = CeresLinearSolver::kDenseNormalCholesky;
  int num_threads = 1;
  // Gauss-Newton only: damping lambda of (H + lambda diag(H)) delta = -g. The first step uses
  // initial_lambda (0: the plain Gauss-Newton step); a step that does not decrease the
  // cost is rejected and retried with lambda = max(10 lambda, min_lambda); an accepted step
  // divides lambda by 10 (back to 0 below min_lambda). The solve stops when lambda > max_lambda.
  double initial_lambda = 0.0;
  double min_lambda = 1e-4;
  double max_lambda = 1e8;
  // Gauss-Newton: stop (converged) after this many consecutive rejected steps; 0 = no limit.
  int max_consecutive_rejections = 0;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Choice("solver", &type,
             ChoiceNames<Type>{{"ceres", Type::kCeres}, {"gauss_newton", Type::kGaussNewton}},
             "Solver of each level's least-squares problem.");
    v.Field("max_iterations", &max_iterations, "Iterations (accepted or rejected) per level.");
    v.Field("function_tolerance", &function_tolerance,
            "Stop when an accepted step lowers the cost by less than this fraction.");
    v.Field("gradient_tolerance", &gradient_tolerance,
            "Stop when the largest tangent-space gradient entry is below this.");
    v.Field("parameter_tolerance", &parameter_tolerance, "Stop when |delta| <= tol (|x| + tol).");
    v.Choice("ceres_linear_solver", &ceres_linear_solver,
             ChoiceNames<CeresLinearSolver>{
                 {"dense_qr", CeresLinearSolver::kDenseQr},
                 {"dense_normal_cholesky", CeresLinearSolver::kDenseNormalCholesky}},
             "Ceres linear solver (ceres only).");
    v.Field("num_threads", &num_threads, "Ceres threads for evaluating residuals (ceres only).");
    v.Field("initial_lambda", &initial_lambda,
            "Gauss-Newton: damping of the first step; 0 is the plain Gauss-Newton step.");
    v.Field("min_lambda", &min_lambda, "Gauss-Newton: damping after the first rejected step.");
    v.Field("max_lambda", &max_lambda, "Gauss-Newton: give up when damping exceeds this.");
    v.Field("max_consecutive_rejections", &max_consecutive_rejections,
            "Gauss-Newton: stop after this many consecutive rejected steps (0: no limit).");
  }
  // "" when valid, otherwise what is wrong.
  std::string Check() const;
};

struct SolverIteration {
  int iteration = 0;  // 0 is the state before the first step
  double cost = 0.0;  // at the current (accepted) parameters
  bool step_accepted = false;
};
// Called after every iteration with the parameter blocks holding the current estimate.
using SolverIterationCallback = std::function<void(const SolverIteration&)>;

struct SolverSummary {
  int iterations = 0;  // steps tried (accepted + rejected)
  int accepted_iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged = false;  // stopped on a tolerance, not on the iteration limit or a failure
  std::string message;
};

class Solver {
 public:
  virtual ~Solver() = default;
  // Minimises the problem in place (its parameter arrays hold the result).
  virtual SolverSummary Solve(LeastSquaresProblem* problem,
                              const SolverIterationCallback& callback = nullptr) const = 0;
};

// The solver options.type names; throws std::invalid_argument when options are invalid.
std::unique_ptr<Solver> MakeSolver(const SolverOptions& options);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_SOLVER_H_
