#include "backend/tracking/tracking_problem_builder.h"

#include <ceres/normal_prior.h>

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "residuals/photometric_residual.h"
#include "residuals/point_to_line_residual.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

std::string Where(int line) { return std::string(__FILE__) + ":" + std::to_string(line) + ": "; }

}  // namespace

std::vector<double> EdgeRowScales(const TrackingReferenceLevel& ref, double max_rows_per_edge) {
  if (!(max_rows_per_edge > 0.0)) return {};
  std::vector<double> scale;
  for (const ReferencePoint& point : ref.points) {
    if (point.edge_id < 0) continue;
    if (point.edge_id >= static_cast<int>(scale.size())) scale.resize(point.edge_id + 1, 0.0);
    scale[point.edge_id] += 1.0;  // the count, for now
  }
  for (double& value : scale) {
    value = value > max_rows_per_edge ? std::sqrt(max_rows_per_edge / value) : 1.0;
  }
  return scale;
}

std::string ProblemBuilderOptions::Check() const {
  if (batch_size < 1) return "batch_size must be >= 1";
  if (!(max_rows_per_edge >= 0.0) || !std::isfinite(max_rows_per_edge)) {
    return "max_rows_per_edge must be >= 0 and finite";
  }
  if (line_finest_level < 0) return "line_finest_level must be >= 0";
  if (!(max_line_rows_per_edge >= 0.0) || !std::isfinite(max_line_rows_per_edge)) {
    return "max_line_rows_per_edge must be >= 0 and finite";
  }
  if (!(brightness_prior_sigma_a > 0.0) || !(brightness_prior_sigma_b > 0.0) ||
      !std::isfinite(brightness_prior_sigma_a) || !std::isfinite(brightness_prior_sigma_b)) {
    return "brightness_prior_sigma_a and brightness_prior_sigma_b must be positive and finite";
  }
  return weighting.Check();
}

std::map<std::string, ProblemBuilderFactory> ProblemBuilderRegistry() {
  std::map<std::string, ProblemBuilderFactory> registry;
  registry["tracking"] = [](const ProblemBuilderOptions& options) {
    return std::make_unique<TrackingProblemBuilder>(options, /*loss_in_problem=*/false);
  };
  registry["tracking_ceres_loss"] = [](const ProblemBuilderOptions& options) {
    return std::make_unique<TrackingProblemBuilder>(options, /*loss_in_problem=*/true);
  };
  return registry;
}

std::unique_ptr<ProblemBuilder> MakeProblemBuilder(const std::string& name,
                                                   const ProblemBuilderOptions& options) {
  const std::map<std::string, ProblemBuilderFactory> registry = ProblemBuilderRegistry();
  const auto it = registry.find(name);
  if (it == registry.end()) {
    std::ostringstream known;
    for (const auto& entry : registry) known << " " << entry.first;
    throw std::invalid_argument(Where(__LINE__) + "unknown problem builder '" + name +
                                "'; known:" + known.str());
  }
  return it->second(options);
}

TrackingProblemBuilder::TrackingProblemBuilder(const ProblemBuilderOptions& options,
                                               bool loss_in_problem)
    : options_(options), loss_in_problem_(loss_in_problem) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument(Where(__LINE__) + error);
  if (loss_in_problem_ && options_.weighting.line_error_model == LineErrorModel::kSharedPerEdge) {
    throw std::invalid_argument(Where(__LINE__) +
                                "line_error_model shared_per_edge mixes the rows of an edge "
                                "before the row-wise loss; use the builder 'tracking'");
  }
}

BuildStatistics TrackingProblemBuilder::Build(const TrackingReference& reference,
                                              const ImagePyramid& current, int level,
                                              double* cur_from_ref, double* brightness,
                                              LeastSquaresProblem* problem) const {
  if (level < 0 || level >= reference.num_levels() || level >= current.num_levels()) {
    throw std::invalid_argument(Where(__LINE__) + "level " + std::to_string(level) +
                                " not in the reference (" + std::to_string(reference.num_levels()) +
                                ") or the current " + "pyramid (" +
                                std::to_string(current.num_levels()) + ")");
  }
  if (problem->ParameterBlockIndex(cur_from_ref) < 0) {
    problem->AddParameterBlock(cur_from_ref, kPoseAmbientSize, std::make_unique<SE3Manifold>());
  }
  const bool with_brightness = options_.brightness == BrightnessModel::kAffine;
  std::vector<double*> photometric_blocks = {cur_from_ref};
  if (with_brightness) {
    if (brightness == nullptr) {
      throw std::invalid_argument(Where(__LINE__) + "brightness affine needs a brightness block");
    }
    photometric_blocks.push_back(brightness);
    if (problem->ParameterBlockIndex(brightness) < 0) {
      problem->AddParameterBlock(brightness, kBrightnessSize);
      // The prior a ~ N(0, sigma_a^2), b ~ N(0, sigma_b^2) (ProblemBuilderOptions): it keeps
      // {a, b} determined where the intensities span a narrow range (only e^a I + b there is).
      Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Zero();
      sqrt_information(0, 0) = 1.0 / options_.brightness_prior_sigma_a;
      sqrt_information(1, 1) = 1.0 / options_.brightness_prior_sigma_b;
      problem->AddResidualBlock(
          std::make_unique<ceres::NormalPrior>(sqrt_information, Eigen::Vector2d::Zero()), nullptr,
          {brightness});
    }
  }
  const TrackingReferenceLevel& ref = reference.levels[level];
  const PinholeCamera& camera = ref.camera;
  const SE3 pose = PoseFromParameters(cur_from_ref);
  // The reference's sigma_I where weighting.intensity_noise is estimated.
  WeightingOptions weighting = options_.weighting;
  weighting.sigma_intensity = IntensityNoiseSigma(weighting, reference.intensity_noise_sigma);
  // With weighting.line_noise estimated, the reference's line noise scale s multiplies every
  // Sigma_l by s^2.
  const double line_noise_scale = reference.line_noise_scale;
  const double line_cov_scale =
      weighting.line_noise == NoiseSource::kEstimated && line_noise_scale > 0.0
          ? line_noise_scale * line_noise_scale
          : 1.0;

  ceres::LossFunction* loss = nullptr;
  if (std::unique_ptr<ceres::LossFunction> made = MakeLossFunction(weighting)) {
    loss = problem->AddLossFunction(std::move(made));
  }
  ceres::LossFunction* loss_inside = loss_in_problem_ ? nullptr : loss;
  ceres::LossFunction* loss_outside = loss_in_problem_ ? loss : nullptr;
  const size_t batch = loss_in_problem_ ? 1 : static_cast<size_t>(options_.batch_size);

  const std::vector<double> edge_row_scale = EdgeRowScales(ref, options_.max_rows_per_edge);

  BuildStatistics stats;
  if (UsesPhotometric(weighting.policy)) {
    std::vector<PhotometricObservation> observations;
    observations.reserve(batch);
    auto flush = [&]() {
      if (observations.empty()) return;
      stats.photometric_residuals += static_cast<int>(observations.size());
      ++stats.residual_blocks;
      problem->AddResidualBlock(std::unique_ptr<ceres::CostFunction>(PhotometricResidual::Create(
                                    current, level, camera, std::move(observations), loss_inside,
                                    options_.interpolation, options_.brightness)),
                                loss_outside, photometric_blocks);
      observations.clear();
      observations.reserve(batch);
    };
    for (const ReferencePoint& point : ref.points) {
      double sqrt_info = PhotometricSqrtInfo(weighting, camera, current, level, pose, point.pixel,
                                             point.idepth, point.idepth_var);
      if (!(sqrt_info > 0.0)) continue;
      if (point.edge_id >= 0 && point.edge_id < static_cast<int>(edge_row_scale.size())) {
        sqrt_info *= edge_row_scale[point.edge_id];
      }
      PhotometricObservation observation;
      observation.pixel_in_ref = point.pixel;
      observation.idepth = point.idepth;
      observation.intensity_ref = point.intensity;
      observation.sqrt_info = sqrt_info;
      observations.push_back(observation);
      if (observations.size() == batch) flush();
    }
    flush();
  }
  const bool shared_line_error = weighting.line_error_model == LineErrorModel::kSharedPerEdge &&
                                 (weighting.policy == WeightingPolicy::kCovariance ||
                                  weighting.policy == WeightingPolicy::kLineOnly);
  const bool lines_at_level = level >= options_.line_finest_level;
  if (lines_at_level && shared_line_error) {
    AddSharedLineErrorBlocks(ref, level, pose, line_cov_scale, loss_inside, cur_from_ref, problem,
                             &stats);
  } else if (lines_at_level && UsesLines(weighting.policy)) {
    const std::vector<double> line_row_scale = EdgeRowScales(ref, options_.max_line_rows_per_edge);
    std::vector<PointToLineObservation> observations;
    observations.reserve(batch);
    auto flush = [&]() {
      if (observations.empty()) return;
      stats.line_residuals += static_cast<int>(observations.size());
      ++stats.residual_blocks;
      problem->AddResidualBlock(std::unique_ptr<ceres::CostFunction>(PointToLineResidual::Create(
                                    camera, std::move(observations), loss_inside)),
                                loss_outside, {cur_from_ref});
      observations.clear();
      observations.reserve(batch);
    };
    for (const ReferencePoint& point : ref.points) {
      const MatchedLine* line = MatchedLineOf(ref, point, level);
      if (line == nullptr) continue;
      LineWithCovariance line_in_cur = line->line_in_cur;
      line_in_cur.cov *= line_cov_scale;
      double sqrt_info = LineSqrtInfo(weighting, camera, pose, point.pixel_on_edge, point.idepth,
                                      point.idepth_var, line_in_cur);
      if (!(sqrt_info > 0.0)) continue;
      if (point.edge_id < static_cast<int>(line_row_scale.size())) {
        sqrt_info *= line_row_scale[point.edge_id];
      }
      PointToLineObservation observation;
      observation.pixel_in_ref = point.pixel_on_edge;
      observation.idepth = point.idepth;
      observation.line_in_cur = line->line_in_cur.line;
      observation.sqrt_info = sqrt_info;
      observations.push_back(observation);
      if (observations.size() == batch) flush();
    }
    flush();
  }
  return stats;
}

void TrackingProblemBuilder::AddSharedLineErrorBlocks(const TrackingReferenceLevel& ref, int level,
                                                      const SE3& pose, double line_cov_scale,
                                                      const ceres::LossFunction* loss,
                                                      double* cur_from_ref,
                                                      LeastSquaresProblem* problem,
                                                      BuildStatistics* stats) const {
  const PinholeCamera& camera = ref.camera;
  std::vector<std::vector<int>> points_of_edge(ref.lines_in_cur.size());
  for (int i = 0; i < static_cast<int>(ref.points.size()); ++i) {
    if (MatchedLineOf(ref, ref.points[i], level) != nullptr) {
      points_of_edge[ref.points[i].edge_id].push_back(i);
    }
  }
  const double edge_pixel_sigma = std::ldexp(options_.weighting.edge_pixel_sigma_px, -level);
  const double edge_pixel_var = edge_pixel_sigma * edge_pixel_sigma;
  std::vector<Eigen::Vector2d> pixels_cur;
  std::vector<double> point_variances;
  for (size_t edge = 0; edge < points_of_edge.size(); ++edge) {
    LineWithCovariance line = ref.lines_in_cur[edge].line_in_cur;
    line.cov *= line_cov_scale;
    std::vector<PointToLineObservation> observations;
    pixels_cur.clear();
    point_variances.clear();
    for (const int i : points_of_edge[edge]) {
      const ReferencePoint& point = ref.points[i];
      Eigen::Vector2d pixel_cur;
      // Rows outside the image at the linearisation point would enter the mix as 0.
      if (!Reproject(camera, pose, point.pixel_on_edge, point.idepth, &pixel_cur) ||
          !camera.IsInside(pixel_cur, 0.0)) {
        continue;
      }
      const Eigen::Matrix3d pixel_cov = ReprojectedPixelCovariance(
          camera, pose, point.pixel_on_edge, point.idepth, point.idepth_var);
      pixels_cur.push_back(pixel_cur);
      point_variances.push_back(
          PointToLineVariance(line.line, Eigen::Matrix3d::Zero(), pixel_cur, pixel_cov) +
          edge_pixel_var);
      PointToLineObservation observation;
      observation.pixel_in_ref = point.pixel_on_edge;
      observation.idepth = point.idepth;
      observation.line_in_cur = line.line;
      observations.push_back(observation);
    }
    if (observations.empty()) continue;
    EdgeLineWeights weights = SharedLineErrorWeights(line, pixels_cur, point_variances);
    for (size_t j = 0; j < observations.size(); ++j) {
      observations[j].sqrt_info = weights.sqrt_info[j];
    }
    stats->line_residuals += static_cast<int>(observations.size());
    ++stats->residual_blocks;
    problem->AddResidualBlock(
        std::unique_ptr<ceres::CostFunction>(PointToLineResidual::Create(
            camera, std::move(observations), loss, std::move(weights.shared))),
        nullptr, {cur_from_ref});
  }
}

}  // namespace pldvo
