// The linear solver of a bundle adjustment's Ceres solve, as a config names it (edge BA,
// windowed BA): the Schur complement on the points or lines (sparse or dense), or sparse Cholesky
// of the whole normal equations. MakeBundleAdjustmentCeresOptions (bundle_adjustment_options.h)
// turns it into Ceres' type.
#ifndef PLDVO_BACKEND_OPTIMIZATION_BA_LINEAR_SOLVER_H_
#define PLDVO_BACKEND_OPTIMIZATION_BA_LINEAR_SOLVER_H_

#include "core/options.h"

namespace pldvo {

enum class BALinearSolver { kSparseSchur, kDenseSchur, kSparseNormalCholesky };
inline const ChoiceNames<BALinearSolver>& BALinearSolverNames() {
  static const ChoiceNames<BALinearSolver> names = {
      {"sparse_schur", BALinearSolver::kSparseSchur},
      {"dense_schur", BALinearSolver::kDenseSchur},
      {"sparse_normal_cholesky", BALinearSolver::kSparseNormalCholesky}};
  return names;
}

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_BA_LINEAR_SOLVER_H_
