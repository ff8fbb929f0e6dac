#include "backend/tracking/tracker.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "backend/optimization/normal_equations.h"
#include "core/wall_clock.h"
#include "residuals/covariance_models.h"
#include "residuals/photometric_residual.h"
#include "residuals/point_to_line_residual.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

std::string Where(int line) { return std::string(__FILE__) + ":" + std::to_string(line) + ": "; }

std::vector<Eigen::Vector2d> ReprojectEdgePixels(const TrackingReferenceLevel& ref, int level,
                                                 const SE3& cur_from_ref) {
  std::vector<Eigen::Vector2d> pixels;
  for (const ReferencePoint& point : ref.points) {
    if (point.edge_id < 0) continue;
    Eigen::Vector2d pixel_cur;
    if (!Reproject(ref.camera, cur_from_ref, point.pixel_on_edge, point.idepth, &pixel_cur)) {
      continue;
    }
    pixels.push_back(PixelAtLevel0(pixel_cur, level));
  }
  return pixels;
}

// Pearson's correlation of the pairs (I_cur, I_ref); 0 for fewer than 2 or constant intensities.
double IntensityCorrelation(const std::vector<Eigen::Vector2d>& cur_ref) {
  if (cur_ref.size() < 2) return 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : cur_ref) mean += p;
  mean /= static_cast<double>(cur_ref.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : cur_ref) scatter += (p - mean) * (p - mean).transpose();
  const double denominator = std::sqrt(scatter(0, 0) * scatter(1, 1));
  return denominator > 0.0 ? scatter(0, 1) / denominator : 0.0;
}

}  // namespace

std::string TrackingOptions::Check() const {
  std::string error = solver.Check();
  if (!error.empty()) return "solver: " + error;
  error = problem.Check();
  if (!error.empty()) return "problem: " + error;
  if (finest_level < 0 || coarsest_level < finest_level) {
    return "need 0 <= finest_level <= coarsest_level";
  }
  if (min_valid_residuals < 0) return "min_valid_residuals must be >= 0";
  if (!(min_valid_fraction >= 0.0 && min_valid_fraction <= 1.0)) {
    return "min_valid_fraction must be in [0, 1]";
  }
  if (!(inlier_threshold > 0.0)) return "inlier_threshold must be > 0";
  if (!(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0)) {
    return "min_inlier_fraction must be in [0, 1]";
  }
  if (!(min_intensity_correlation >= -1.0 && min_intensity_correlation <= 1.0)) {
    return "min_intensity_correlation must be in [-1, 1]";
  }
  return "";
}

const char* TrackingStatusName(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::kConverged:
      return "converged";
    case TrackingStatus::kNotConverged:
      return "not_converged";
    case TrackingStatus::kLost:
      return "lost";
  }
  return "unknown";
}

int TrackingResult::TotalIterations() const {
  int total = 0;
  for (const LevelResult& level : levels) total += level.iterations;
  return total;
}

ResidualStatistics EvaluateResidualStatistics(const LeastSquaresProblem& problem,
                                              double inlier_threshold,
                                              bool with_intensity_correlation) {
  ResidualStatistics stats;
  std::vector<double> residuals(problem.MaxBlockResiduals());
  const size_t error_rows = with_intensity_correlation ? residuals.size() : 0;
  std::vector<double> errors(error_rows);
  std::vector<std::uint8_t> error_valid(error_rows);
  std::vector<Eigen::Vector2d> cur_ref;  // (I_cur, I_ref) of the valid photometric rows
  for (const LeastSquaresProblem::ResidualBlock& block : problem.residual_blocks()) {
    const int rows = block.cost_function->num_residuals();
    if (!block.cost_function->Evaluate(block.parameters.data(), residuals.data(), nullptr)) {
      continue;
    }
    double sq_norm = 0.0;
    for (int i = 0; i < rows; ++i) sq_norm += residuals[i] * residuals[i];
    double block_cost = 0.5 * sq_norm;
    if (block.loss_function != nullptr) {
      double rho[3];
      block.loss_function->Evaluate(sq_norm, rho);
      block_cost = 0.5 * rho[0];
    }
    stats.cost += block_cost;
    stats.rows += rows;
    // valid(i) reflects the Evaluate above.
    const auto* photometric = dynamic_cast<const PhotometricResidual*>(block.cost_function);
    const auto* line = dynamic_cast<const PointToLineResidual*>(block.cost_function);
    if (photometric != nullptr) stats.photometric_cost += block_cost;
    if (photometric != nullptr && with_intensity_correlation) {
      photometric->IntensityErrors(PoseFromParameters(block.parameters[0]), errors.data(),
                                   error_valid.data());
      for (int i = 0; i < rows; ++i) {
        const double intensity_ref = photometric->observations()[i].intensity_ref;
        if (!error_valid[i]) continue;
        cur_ref.emplace_back(intensity_ref - errors[i], intensity_ref);
        stats.photometric_errors.push_back(errors[i]);
        stats.photometric_sqrt_info.push_back(photometric->observations()[i].sqrt_info);
      }
    }
    for (int i = 0; i < rows; ++i) {
      const bool valid = photometric != nullptr ? photometric->valid(i)
                         : line != nullptr      ? line->valid(i)
                                                : true;
      if (!valid) continue;
      ++stats.valid_rows;
      stats.photometric_valid_rows += photometric != nullptr;
      double magnitude = std::abs(residuals[i]);
      if (block.loss_function != nullptr) {
        double rho[3];
        block.loss_function->Evaluate(magnitude * magnitude, rho);
        magnitude = std::sqrt(std::max(rho[0], 0.0));
      }
      if (magnitude <= inlier_threshold) ++stats.inlier_rows;
    }
  }
  stats.intensity_correlation = IntensityCorrelation(cur_ref);
  return stats;
}

namespace {

// The pose block of (J~^T J~)^-1 at the problem's current parameters; zero when H is singular.
Matrix6d PoseCovarianceAtSolution(const LeastSquaresProblem& problem, const double* pose) {
  NormalEquations equations(problem);
  double cost = 0.0;
  const int index = problem.ParameterBlockIndex(pose);
  if (index < 0 || equations.TangentOffset(index) < 0 || !equations.Linearize(&cost)) {
    return Matrix6d::Zero();
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(equations.hessian());
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return Matrix6d::Zero();
  const Eigen::MatrixXd inverse =
      ldlt.solve(Eigen::MatrixXd::Identity(equations.dimension(), equations.dimension()));
  const int offset = equations.TangentOffset(index);
  return inverse.block<6, 6>(offset, offset);
}

}  // namespace

Tracker::Tracker(const TrackingOptions& options) : options_(options) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument(Where(__LINE__) + "tracking: " + error);
  builder_ = MakeProblemBuilder(options_.problem_builder, options_.problem);
  solver_ = MakeSolver(options_.solver);
}

double Tracker::IntensityNoiseAtSolution(const TrackingReference& reference,
                                         const ResidualStatistics& stats) const {
  const WeightingOptions& weighting = options_.problem.weighting;
  const double noise_factor = IntensityNoiseFactor(weighting.policy);
  const double sigma_used = IntensityNoiseSigma(weighting, reference.intensity_noise_sigma);
  // Each row's variance was noise_factor sigma_used^2 + D_i: recover D_i from its sqrt_info.
  std::vector<double> errors, other_variances;
  for (size_t i = 0; i < stats.photometric_errors.size(); ++i) {
    const double sqrt_info = stats.photometric_sqrt_info[i];
    if (!(sqrt_info > 0.0)) continue;
    errors.push_back(stats.photometric_errors[i]);
    other_variances.push_back(
        std::max(0.0, 1.0 / (sqrt_info * sqrt_info) - noise_factor * sigma_used * sigma_used));
  }
  return EstimateIntensityNoiseSigma(errors, other_variances, noise_factor);
}

double Tracker::LineNoiseAtSolution(const TrackingReference& reference,
                                    const SE3& cur_from_ref) const {
  const WeightingOptions& weighting = options_.problem.weighting;
  if (weighting.policy != WeightingPolicy::kCovariance &&
      weighting.policy != WeightingPolicy::kLineOnly) {
    return 0.0;
  }
  const TrackingReferenceLevel& ref = reference.levels[options_.finest_level];
  // The builder's point part of a row: shared_per_edge adds the edge pixel's own error.
  const double edge_pixel_sigma =
      weighting.line_error_model == LineErrorModel::kSharedPerEdge
          ? std::ldexp(weighting.edge_pixel_sigma_px, -options_.finest_level)
          : 0.0;
  std::vector<double> errors, depth_variances, line_variances;
  for (const ReferencePoint& point : ref.points) {
    const MatchedLine* matched = MatchedLineOf(ref, point, options_.finest_level);
    if (matched == nullptr) continue;
    const LineWithCovariance& line = matched->line_in_cur;
    Eigen::Vector2d pixel_cur;
    if (!Reproject(ref.camera, cur_from_ref, point.pixel_on_edge, point.idepth, &pixel_cur) ||
        !ref.camera.IsInside(pixel_cur, 0.0)) {
      continue;
    }
    const Eigen::Matrix3d pixel_cov = ReprojectedPixelCovariance(
        ref.camera, cur_from_ref, point.pixel_on_edge, point.idepth, point.idepth_var);
    errors.push_back(line.line.dot(pixel_cur.homogeneous()));
    depth_variances.push_back(
        PointToLineVariance(line.line, Eigen::Matrix3d::Zero(), pixel_cur, pixel_cov) +
        edge_pixel_sigma * edge_pixel_sigma);
    line_variances.push_back(
        PointToLineVariance(line.line, line.cov, pixel_cur, Eigen::Matrix3d::Zero()));
  }
  return EstimateLineNoiseScale(errors, depth_variances, line_variances);
}

TrackingResult Tracker::Track(const TrackingReference& reference, const ImagePyramid& current,
                              const SE3& initial_cur_from_ref,
                              const AffineBrightness& initial_brightness,
                              const TrackingIterationCallback& callback) const {
  return TrackLevels(reference, current, initial_cur_from_ref, initial_brightness, callback,
                     options_.coarsest_level);
}

TrackingResult Tracker::Refine(const TrackingReference& reference, const ImagePyramid& current,
                               const SE3& cur_from_ref, const AffineBrightness& brightness) const {
  return TrackLevels(reference, current, cur_from_ref, brightness, nullptr, options_.finest_level);
}

TrackingResult Tracker::TrackLevels(const TrackingReference& reference, const ImagePyramid& current,
                                    const SE3& initial_cur_from_ref,
                                    const AffineBrightness& initial_brightness,
                                    const TrackingIterationCallback& callback,
                                    int coarsest_level) const {
  const int available = std::min(reference.num_levels(), current.num_levels());
  if (available <= options_.finest_level) {
    throw std::invalid_argument(Where(__LINE__) + "finest_level " +
                                std::to_string(options_.finest_level) + " but only " +
                                std::to_string(available) + " levels available");
  }
  const int coarsest = std::min(coarsest_level, available - 1);

  double pose[kPoseAmbientSize];
  PoseToParameters(initial_cur_from_ref, pose);
  double brightness[kBrightnessSize] = {initial_brightness.a, initial_brightness.b};
  const auto start = WallClock::now();
  TrackingResult result;
  result.initial_cur_from_ref = initial_cur_from_ref;
  result.initial_brightness = initial_brightness;
  for (int level = coarsest; level >= options_.finest_level; --level) {
    LeastSquaresProblem problem;
    const BuildStatistics built =
        builder_->Build(reference, current, level, pose, brightness, &problem);
    LevelResult level_result;
    level_result.level = level;
    level_result.residual_rows = built.photometric_residuals + built.line_residuals;
    level_result.line_rows = built.line_residuals;

    SolverIterationCallback solver_callback;
    if (callback) {
      const TrackingReferenceLevel& ref = reference.levels[level];
      solver_callback = [&, level](const SolverIteration& iteration) {
        TrackingIteration info;
        info.level = level;
        info.iteration = iteration.iteration;
        info.cost = iteration.cost;
        info.step_accepted = iteration.step_accepted;
        info.cur_from_ref = PoseFromParameters(pose);
        if (options_.record_edge_pixels) {
          info.edge_pixels_in_cur = ReprojectEdgePixels(ref, level, info.cur_from_ref);
        }
        callback(info);
      };
    }
    if (problem.residual_blocks().empty()) {
      level_result.solver_message = "no residuals";
      result.levels.push_back(level_result);
      continue;
    }
    const SolverSummary summary = solver_->Solve(&problem, solver_callback);
    level_result.iterations = summary.iterations;
    level_result.initial_cost = summary.initial_cost;
    level_result.converged = summary.converged;
    level_result.solver_message = summary.message;
    const ResidualStatistics final_stats =
        EvaluateResidualStatistics(problem, options_.inlier_threshold,
                                   /*with_intensity_correlation=*/level == options_.finest_level);
    level_result.final_cost = final_stats.cost;
    level_result.valid_rows = final_stats.valid_rows;
    level_result.inlier_rows = final_stats.inlier_rows;
    level_result.photometric_valid_rows = final_stats.photometric_valid_rows;
    level_result.intensity_correlation = final_stats.intensity_correlation;
    level_result.rms = final_stats.valid_rows > 0
                           ? std::sqrt(2.0 * final_stats.cost / final_stats.valid_rows)
                           : 0.0;
    level_result.photometric_rms =
        final_stats.photometric_valid_rows > 0
            ? std::sqrt(2.0 * final_stats.photometric_cost / final_stats.photometric_valid_rows)
            : 0.0;
    result.levels.push_back(level_result);
    if (options_.pose_covariance && level == options_.finest_level) {
      result.pose_covariance = PoseCovarianceAtSolution(problem, pose);
    }
    if (level == options_.finest_level) {
      result.intensity_noise_sigma = IntensityNoiseAtSolution(reference, final_stats);
      result.line_noise_scale = LineNoiseAtSolution(reference, PoseFromParameters(pose));
    }
  }

  result.cur_from_ref = PoseFromParameters(pose);
  result.brightness = {brightness[0], brightness[1]};
  const LevelResult& finest = result.levels.back();
  result.valid_residuals = finest.valid_rows;
  result.final_rms = finest.rms;
  result.final_photometric_rms = finest.photometric_rms;
  result.inlier_fraction =
      finest.valid_rows > 0 ? static_cast<double>(finest.inlier_rows) / finest.valid_rows : 0.0;
  result.intensity_correlation = finest.intensity_correlation;
  const bool lost = finest.valid_rows < std::max(1, options_.min_valid_residuals) ||
                    finest.valid_rows < options_.min_valid_fraction * finest.residual_rows ||
                    result.inlier_fraction < options_.min_inlier_fraction ||
                    (finest.photometric_valid_rows > 0 &&
                     result.intensity_correlation < options_.min_intensity_correlation);
  if (lost) {
    result.status = TrackingStatus::kLost;
  } else {
    result.status = finest.converged ? TrackingStatus::kConverged : TrackingStatus::kNotConverged;
  }
  result.ms = MsSince(start);
  return result;
}

}  // namespace pldvo
