// Coarse-to-fine direct tracking of the current frame against a reference keyframe (seed paper
// Sec. IV). For each pyramid level from `coarsest_level` down to `finest_level`:
//   1. the problem builder adds the level's photometric and point-to-line residual blocks with
//      weights (eqs. 5-6) computed at the current estimate, the linearisation point;
//   2. the solver minimises the weighted robust sum of the photometric (eq. 2) and point-to-line
//      (eq. 3) residuals by Gauss-Newton steps delta_xi = -(J^T W J)^-1 J^T W E (the
//      paper's Sec. IV update, not numbered there), xi <- Exp(delta_xi) * xi, until a tolerance or
//      the iteration limit is met (SolverOptions); docs/tracking.md discusses the equation
//      numbering;
//   3. the estimate seeds the next finer level.
// After the finest level the valid residuals and the RMS of the whitened (robustified)
// residuals at the final pose decide the status:
//   kLost        fewer than min_valid_residuals valid rows, or fewer than min_valid_fraction of
//                the rows added at the finest level still valid, or fewer than
//                min_inlier_fraction of the valid rows inliers (|r~| <= inlier_threshold, r~ the
//                whitened, robustified residual: the LSD-SLAM "good pixel" ratio), or, when
//                the finest level has photometric rows, a correlation of I_ref and I_cur over
//                them below min_intensity_correlation (docs/tracking.md, "Lost detection
//                against unrelated images": the whitened fraction passes noise images, whose
//                run-away translation inflates the depth term of Sigma_r; the correlation,
//                free of Sigma_r, of gain and of bias, does not);
//   kConverged   otherwise, when the finest level's solver stopped on a tolerance;
//   kNotConverged otherwise (iteration limit at the finest level).
#ifndef PLDVO_BACKEND_TRACKING_TRACKER_H_
#define PLDVO_BACKEND_TRACKING_TRACKER_H_

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "backend/optimization/solver.h"
#include "backend/tracking/problem_builder.h"
#include "backend/tracking/tracking_reference.h"
#include "core/image_pyramid.h"
#include "core/options.h"
#include "core/se3.h"
#include "residuals/affine_brightness.h"

namespace pldvo {

struct TrackingOptions {
  // Solver type ("solver": ceres | gauss_newton), iterations and tolerances per level; keys sit
  // directly under tracking. (tracking.solver, tracking.max_iterations, ...).
  SolverOptions solver;
  std::string problem_builder = "tracking";
  ProblemBuilderOptions problem;
  // Levels solved, coarse to fine; clamped to the levels the reference and image have.
  int coarsest_level = 3;
  int finest_level = 0;
  // Loss-of-track thresholds, evaluated at the final pose of the finest level.
  int min_valid_residuals = 30;
  double min_valid_fraction = 0.3;
  double inlier_threshold = 2.0;  // whitened units: 2 sigma of the residual model
  double min_inlier_fraction = 0.3;
  double min_intensity_correlation = 0.4;
  // Compute the reprojected edge pixels for the iteration callback (the paper's Fig. 2).
  bool record_edge_pixels = true;
  // Compute the pose covariance (J^T J)^-1 of the finest level at the solution
  // (TrackingResult::pose_covariance); the odometry hands it to the mapping's stereo.
  bool pose_covariance = false;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    solver.VisitFields(v);
    v.Field("problem_builder", &problem_builder,
            "Registered problem builder: tracking | tracking_ceres_loss.");
    v.Section("problem", &problem, "Residual layout and weighting of the problem builder.");
    v.Field("coarsest_level", &coarsest_level, "First (coarsest) pyramid level solved.");
    v.Field("finest_level", &finest_level, "Last (finest) pyramid level solved.");
    v.Field("min_valid_residuals", &min_valid_residuals,
            "Lost when fewer residual rows are valid at the final pose.");
    v.Field("min_valid_fraction", &min_valid_fraction,
            "Lost when fewer than this fraction of the finest level's rows stay valid.");
    v.Field("inlier_threshold", &inlier_threshold,
            "A valid row is an inlier when its whitened robustified residual is below this.");
    v.Field("min_inlier_fraction", &min_inlier_fraction,
            "Lost when fewer than this fraction of the valid rows are inliers.");
    v.Field("min_intensity_correlation", &min_intensity_correlation,
            "Lost when the correlation of I_ref and I_cur over the valid photometric rows is "
            "below this (0.4; -1: off).");
    v.Field("record_edge_pixels", &record_edge_pixels,
            "Give the iteration callback the reprojected edge pixels (Fig. 2).");
    v.Field("pose_covariance", &pose_covariance,
            "Compute the pose covariance (J^T J)^-1 at the finest level's solution; the "
            "mapping adds it to the epipolar line error of its stereo (default false).");
  }
  std::string Check() const;
};

enum class TrackingStatus { kConverged, kNotConverged, kLost };
const char* TrackingStatusName(TrackingStatus status);

struct LevelResult {
  int level = 0;
  int iterations = 0;
  int residual_rows = 0;  // added by the builder
  int line_rows = 0;      // of them, point-to-line rows
  int valid_rows = 0;     // valid at the level's final pose
  int inlier_rows = 0;    // valid with |r~| <= inlier_threshold
  int photometric_valid_rows = 0;
  // Over the valid photometric rows (0 with fewer than 2); computed at the finest level only.
  double intensity_correlation = 0.0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double rms = 0.0;              // sqrt(2 final_cost / valid_rows)
  double photometric_rms = 0.0;  // the same over the photometric rows (0 without any)
  bool converged = false;
  std::string solver_message;
};

struct TrackingResult {
  SE3 cur_from_ref;
  // The current frame's brightness relative to the reference (tracking.problem.brightness
  // affine; the initial guess, unchanged, with none).
  AffineBrightness brightness;
  SE3 initial_cur_from_ref;             // the initial guess this result was solved from
  AffineBrightness initial_brightness;  // and brightness
  double ms = 0.0;                      // wall time of the Track call
  TrackingStatus status = TrackingStatus::kLost;
  std::vector<LevelResult> levels;     // in the order solved (coarse to fine)
  int valid_residuals = 0;             // at the final pose, finest level
  double inlier_fraction = 0.0;        // inlier_rows / valid_rows at the finest level
  double intensity_correlation = 0.0;  // the finest level's
  double final_rms = 0.0;
  double final_photometric_rms = 0.0;  // finest level, photometric rows only (0 without any)
  // The image noise sigma_I (gray levels) the finest level's photometric errors imply at the
  // solution (EstimateIntensityNoiseSigma); 0 when there are too few rows or sigma_I does not
  // enter the policy.
  double intensity_noise_sigma = 0.0;
  // The scale s of the lines' covariance the finest level's point-to-line errors imply at the
  // solution (EstimateLineNoiseScale), whichever weighting.line_noise; 0 when there are too few
  // line rows or Sigma_l does not enter the policy.
  double line_noise_scale = 0.0;
  // With TrackingOptions::pose_covariance: (J~^T J~)^-1 of the finest level at cur_from_ref,
  // the pose block of it when the brightness is estimated too (whitened, robustified rows, so
  // the inverse of the Gauss-Newton normal matrix); zero otherwise or when J~ is rank deficient.
  Matrix6d pose_covariance = Matrix6d::Zero();
  int TotalIterations() const;
};

struct TrackingIteration {
  int level = 0;
  int iteration = 0;  // 0: the level's initial state
  double cost = 0.0;
  bool step_accepted = false;
  SE3 cur_from_ref;
  // With record_edge_pixels: the reference points on edges reprojected with cur_from_ref, in
  // level-0 pixels of the current image (points reprojecting behind the camera left out).
  std::vector<Eigen::Vector2d> edge_pixels_in_cur;
};
using TrackingIterationCallback = std::function<void(const TrackingIteration&)>;

struct ResidualStatistics;

class Tracker {
 public:
  // Throws std::invalid_argument on invalid options or an unknown problem builder.
  explicit Tracker(const TrackingOptions& options);

  // Aligns `current` (the current frame's pyramid) to `reference`, starting from
  // initial_cur_from_ref and (with tracking.problem.brightness affine) initial_brightness. The
  // camera of every level is the reference's.
  TrackingResult Track(const TrackingReference& reference, const ImagePyramid& current,
                       const SE3& initial_cur_from_ref,
                       const AffineBrightness& initial_brightness = AffineBrightness(),
                       const TrackingIterationCallback& callback = nullptr) const;

  // Track() over the finest level only, from a pose already tracked on the same reference: the
  // coarse levels widen the basin of convergence, which a converged pose does not need (the
  // odometry re-solves with it after unmatching wrong line matches).
  TrackingResult Refine(const TrackingReference& reference, const ImagePyramid& current,
                        const SE3& cur_from_ref, const AffineBrightness& brightness) const;

  const TrackingOptions& options() const { return options_; }

 private:
  // Track() from `coarsest_level` (clamped to the pyramids) down to the finest level.
  TrackingResult TrackLevels(const TrackingReference& reference, const ImagePyramid& current,
                             const SE3& initial_cur_from_ref,
                             const AffineBrightness& initial_brightness,
                             const TrackingIterationCallback& callback, int coarsest_level) const;

  // TrackingResult::intensity_noise_sigma from the finest level's statistics.
  double IntensityNoiseAtSolution(const TrackingReference& reference,
                                  const ResidualStatistics& stats) const;

  // TrackingResult::line_noise_scale at the finest level's solution `cur_from_ref`.
  double LineNoiseAtSolution(const TrackingReference& reference, const SE3& cur_from_ref) const;

  TrackingOptions options_;
  std::unique_ptr<ProblemBuilder> builder_;
  std::unique_ptr<Solver> solver_;
};

// Valid rows, inliers and cost of a problem at its current parameters: evaluates every block;
// rows of PhotometricResidual / PointToLineResidual count when valid, rows of other cost
// functions always count. A valid row is an inlier when |r~| <= inlier_threshold, with r~ the
// row as evaluated, or sign(r) sqrt(rho(r^2)) for a block with a LossFunction. The intensity
// correlation is Pearson's, of (I_cur, I_ref) over the valid PhotometricResidual rows
// (PhotometricResidual::IntensityErrors gives I_cur = I_ref - e), computed only when
// `with_intensity_correlation`; 0 for fewer than 2 rows or constant intensities.
struct ResidualStatistics {
  int rows = 0;
  int valid_rows = 0;
  int inlier_rows = 0;
  double cost = 0.0;
  // The PhotometricResidual blocks alone.
  int photometric_valid_rows = 0;
  double intensity_correlation = 0.0;
  double photometric_cost = 0.0;
  // With `with_intensity_correlation`: the valid photometric rows' errors (no sqrt_info, no
  // loss) and their sqrt_info.
  std::vector<double> photometric_errors;
  std::vector<double> photometric_sqrt_info;
};
ResidualStatistics EvaluateResidualStatistics(const LeastSquaresProblem& problem,
                                              double inlier_threshold,
                                              bool with_intensity_correlation);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_TRACKING_TRACKER_H_
