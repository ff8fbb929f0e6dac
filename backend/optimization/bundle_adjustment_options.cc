#include "backend/optimization/bundle_adjustment_options.h"

namespace pldvo {

ceres::Solver::Options MakeBundleAdjustmentCeresOptions(BALinearSolver linear_solver,
                                                        int max_iterations,
                                                        double function_tolerance,
                                                        int num_threads) {
  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = function_tolerance;
  options.num_threads = num_threads;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  const bool suitesparse = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE);
  options.sparse_linear_algebra_library_type =
      suitesparse ? ceres::SUITE_SPARSE : ceres::EIGEN_SPARSE;
  switch (linear_solver) {
    case BALinearSolver::kSparseSchur:
      options.linear_solver_type = ceres::SPARSE_SCHUR;
      break;
    case BALinearSolver::kDenseSchur:
      options.linear_solver_type = ceres::DENSE_SCHUR;
      break;
    case BALinearSolver::kSparseNormalCholesky:
      options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
      break;
  }
  return options;
}

}  // namespace pldvo
