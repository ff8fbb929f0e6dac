#include "backend/optimization/solver.h"

#include <stdexcept>

#include "backend/optimization/ceres_solver.h"
#include "backend/optimization/gauss_newton_solver.h"

namespace pldvo {

std::string SolverOptions::Check() const {
  if (max_iterations < 0) return "max_iterations must be >= 0";
  if (function_tolerance < 0.0 || gradient_tolerance < 0.0 || parameter_tolerance < 0.0) {
    return "tolerances must be >= 0";
  }
  if (num_threads < 1) return "num_threads must be >= 1";
  if (max_consecutive_rejections < 0) return "max_consecutive_rejections must be >= 0";
  if (initial_lambda < 0.0 || min_lambda <= 0.0 || max_lambda < min_lambda) {
    return "need initial_lambda >= 0 and 0 < min_lambda <= max_lambda";
  }
  return "";
}

std::unique_ptr<Solver> MakeSolver(const SolverOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": invalid solver options: " + error);
  }
  if (options.type == SolverOptions::Type::kCeres) return std::make_unique<CeresSolver>(options);
  return std::make_unique<GaussNewtonSolver>(options);
}

}  // namespace pldvo
