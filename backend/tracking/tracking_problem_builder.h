// The tracking problem of one pyramid level (seed paper Sec. IV): for the pose xi = cur_from_ref,
//
//   E(xi) = sum_i rho((r_i / sigma_ri)^2) + sum_j rho((g_j / sigma_gj)^2)        (eq. 1)
//
// with the photometric residuals r_i = I_ref(x_i) - I_cur(tau(x_i, d_i, xi)) of every reference
// point (eq. 2, residuals/photometric_residual.h; I_cur sampled bilinearly or bicubically as
// `interpolation` says) and the point-to-line residuals
// g_j = l_j^T tau(x_j, d_j, xi) of every point on an edge with a matched current line
// (eq. 3, residuals/point_to_line_residual.h). The variances sigma^2 (eqs. 5-6) come from
// residuals/weighting.h at the linearisation point (the pose held by the parameter block when
// Build is called) under the configured policy; a family whose policy weight is 0
// (photometric_only, line_only) is not added, nor is a row whose weight is 0 at the
// linearisation point (reprojection invalid there).
//
// With brightness affine the photometric rows also read the brightness block {a, b}
// (residuals/affine_brightness.h), which gets the prior N(0, diag(sigma_a^2, sigma_b^2)) as a
// ceres::NormalPrior block.
//
// Layout: consecutive rows are grouped into blocks of `batch_size` rows sharing the pose block,
// with the robust loss applied row-wise in square-root form inside the cost functions. With
// `loss_in_problem` (registry name "tracking_ceres_loss") every row is its own block and the
// robust loss is passed with it as a ceres::LossFunction instead. With line_error_model
// shared_per_edge (builder "tracking" only) the point-to-line rows form one block per edge,
// whitened against the line error its pixels share. With max_rows_per_edge > 0 the photometric
// rows of an edge with more points than that are down-weighted (EdgeRowScales), and with
// max_line_rows_per_edge > 0 its point-to-line rows alike; levels below line_finest_level get no
// point-to-line rows.
#ifndef PLDVO_BACKEND_TRACKING_TRACKING_PROBLEM_BUILDER_H_
#define PLDVO_BACKEND_TRACKING_TRACKING_PROBLEM_BUILDER_H_

#include <vector>

#include "backend/tracking/problem_builder.h"

namespace pldvo {

// Per edge id of the level's points, the factor on its photometric rows' sqrt_info:
// sqrt(max_rows_per_edge / n) for an edge with n > max_rows_per_edge points, else 1 (the rows of
// an edge then carry at most max_rows_per_edge points' information). Empty when
// max_rows_per_edge is 0 (off).
std::vector<double> EdgeRowScales(const TrackingReferenceLevel& ref, double max_rows_per_edge);

class TrackingProblemBuilder : public ProblemBuilder {
 public:
  // Throws std::invalid_argument on invalid options.
  TrackingProblemBuilder(const ProblemBuilderOptions& options, bool loss_in_problem);

  BuildStatistics Build(const TrackingReference& reference, const ImagePyramid& current, int level,
                        double* cur_from_ref, double* brightness,
                        LeastSquaresProblem* problem) const override;

 private:
  // line_error_model shared_per_edge: one block per matched edge, its rows whitened against the
  // shared line error (residuals/weighting.h SharedLineErrorWeights).
  void AddSharedLineErrorBlocks(const TrackingReferenceLevel& ref, int level, const SE3& pose,
                                double line_cov_scale, const ceres::LossFunction* loss,
                                double* cur_from_ref, LeastSquaresProblem* problem,
                                BuildStatistics* stats) const;

  ProblemBuilderOptions options_;
  bool loss_in_problem_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_TRACKING_TRACKING_PROBLEM_BUILDER_H_
