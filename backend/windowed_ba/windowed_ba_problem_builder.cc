#include "backend/windowed_ba/windowed_ba_problem_builder.h"

#include <ceres/normal_prior.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "backend/optimization/problem_builder_registry.h"
#include "backend/windowed_ba/point_selection.h"
#include "residuals/baseline_prior_residual.h"
#include "residuals/host_target_photometric_residual.h"
#include "residuals/host_target_point_to_line_residual.h"
#include "residuals/pose_prior_residual.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

std::string Where(int line) { return std::string(__FILE__) + ":" + std::to_string(line) + ": "; }

// DSO's residual pattern 8 (offsets within 2 px of the point).
constexpr double kDso8Pattern[8][2] = {{0, -2}, {-1, -1}, {1, -1}, {-2, 0},
                                       {0, 0},  {2, 0},   {-1, 1}, {0, 2}};

// The builder of both registry entries; `loss_in_problem` chooses where the robust loss goes.
class PhotometricLineWindowBuilder : public WindowedBAProblemBuilder {
 public:
  PhotometricLineWindowBuilder(const WindowedBAOptions& options, bool loss_in_problem)
      : options_(options), loss_in_problem_(loss_in_problem) {
    const std::string error = options_.Check();
    if (!error.empty()) throw std::invalid_argument(Where(__LINE__) + error);
  }

  WindowedBAProblem Build(const WindowedBAWindow& window) const override;

 private:
  // Holds the scale: the baseline prior of the header, or the second pose constant.
  void AddScaleGauge(WindowedBAProblem* problem) const;
  // The prior's residual block on the window keyframes it constrains (none when the window
  // still holds a keyframe it has marginalised, or it constrains none of them).
  void AddPrior(const WindowedBAWindow& window, WindowedBAProblem* problem) const;

  WindowedBAOptions options_;
  bool loss_in_problem_;
};

// Mean of r_k^2 over a pattern's whitened rows (no robust loss) at the given parameters.
double MeanRowEnergy(const ImagePyramid& target_pyramid, const PinholeCamera& camera,
                     const std::vector<HostPixel>& pattern, const std::array<double, 7>& host_pose,
                     const std::array<double, 7>& target_pose, double idepth,
                     const std::array<double, 2>& host_brightness,
                     const std::array<double, 2>& target_brightness) {
  const HostTargetPhotometricResidual residual(target_pyramid, 0, camera, pattern);
  const double* parameters[] = {host_pose.data(), target_pose.data(), &idepth,
                                host_brightness.data(), target_brightness.data()};
  double rows[8];
  if (pattern.size() > 8 || !residual.Evaluate(parameters, rows, nullptr)) return 0.0;
  double energy = 0.0;
  for (size_t k = 0; k < pattern.size(); ++k) energy += rows[k] * rows[k];
  return energy / static_cast<double>(pattern.size());
}

Eigen::Vector3d Centre(const double* cam_from_world) {
  return PoseFromParameters(cam_from_world).Inverse().translation();
}

void PhotometricLineWindowBuilder::AddScaleGauge(WindowedBAProblem* out) const {
  const int n = static_cast<int>(out->poses.size());
  const Eigen::Vector3d oldest = Centre(out->poses[0].data());
  double largest = 0.0;
  int farthest = 1;
  for (int k = 1; k < n; ++k) {
    const double baseline = (Centre(out->poses[k].data()) - oldest).norm();
    if (baseline > largest) {
      largest = baseline;
      farthest = k;
    }
  }
  if (!(largest > 0.0)) {
    out->problem.SetParameterBlockConstant(out->poses[1].data());
    return;
  }
  const double next = (Centre(out->poses[1].data()) - oldest).norm();
  const int partner = next >= 1e-3 * largest ? 1 : farthest;
  out->baseline_keyframe_a = 0;
  out->baseline_keyframe_b = partner;
  out->baseline = partner == 1 ? next : largest;
  out->problem.AddResidualBlock(
      std::unique_ptr<ceres::CostFunction>(BaselinePriorResidual::Create(
          out->baseline, options_.baseline_prior_sigma_ratio * out->baseline)),
      nullptr, {out->poses[0].data(), out->poses[partner].data()});
}

void PhotometricLineWindowBuilder::AddPrior(const WindowedBAWindow& window,
                                            WindowedBAProblem* out) const {
  const WindowedBAPrior& prior = *window.prior;
  std::vector<int> ids;
  for (const int index : out->keyframe_indices) {
    const int id = window.keyframes[index].id;
    if (id <= prior.marginalized_through_id) return;
    ids.push_back(id);
  }
  WindowedBAPrior kept;
  if (!KeepKeyframes(prior, ids, &kept)) return;
  std::vector<double*> poses;
  for (const int id : kept.keyframe_ids) {
    poses.push_back(out->poses[std::find(ids.begin(), ids.end(), id) - ids.begin()].data());
  }
  if (!(kept.information.diagonal().maxCoeff() > 0.0)) return;
  out->prior_block = out->problem.AddResidualBlock(
      std::make_unique<PosePriorResidual>(kept.cam_from_world, kept.information, kept.gradient),
      nullptr, poses);
  out->num_prior_keyframes = static_cast<int>(poses.size());
}

WindowedBAProblem PhotometricLineWindowBuilder::Build(const WindowedBAWindow& window) const {
  CheckWindowedBAWindow(window);
  const PinholeCamera& camera = window.camera;
  const int total = static_cast<int>(window.keyframes.size());
  const int n = std::min(options_.window, total);
  WindowedBAProblem out;
  for (int k = total - n; k < total; ++k) out.keyframe_indices.push_back(k);
  auto keyframe = [&](int position) -> const WindowedBAKeyframe& {
    return window.keyframes[out.keyframe_indices[position]];
  };
  out.poses.resize(n);
  out.brightness.resize(n);
  for (int k = 0; k < n; ++k) {
    PoseToParameters(keyframe(k).cam_from_world, out.poses[k].data());
    out.brightness[k] = {keyframe(k).brightness.a, keyframe(k).brightness.b};
  }

  // Point selection, before any block is added: `idepths` must not reallocate afterwards.
  const bool dso8 = options_.pattern == WindowedBAPattern::kDso8;
  const double pattern_radius = dso8 ? 2.0 : 0.0;
  const int hosts =
      options_.newest_keyframe_points == NewestKeyframePoints::kTargetOnly && n > 1 ? n - 1 : n;
  const int budget = options_.max_points / hosts;
  for (int k = 0; k < hosts; ++k) {
    for (const int index : SelectWindowPoints(keyframe(k).points, *keyframe(k).pyramid, budget,
                                              options_.min_gradient, pattern_radius)) {
      out.points.push_back({k, index});
    }
  }
  out.num_candidates = static_cast<int>(out.points.size());
  out.idepths.reserve(out.points.size());

  LeastSquaresProblem& problem = out.problem;
  for (int k = 0; k < n; ++k) {
    problem.AddParameterBlock(out.poses[k].data(), kPoseAmbientSize,
                              std::make_unique<SE3Manifold>());
    problem.AddParameterBlock(out.brightness[k].data(), kBrightnessSize);
  }
  problem.SetParameterBlockConstant(out.poses[0].data());
  problem.SetParameterBlockConstant(out.brightness[0].data());
  const bool affine = options_.brightness == BrightnessModel::kAffine;
  for (int k = 1; k < n; ++k) {
    if (!affine) {
      problem.SetParameterBlockConstant(out.brightness[k].data());
      continue;
    }
    Eigen::Matrix2d sqrt_information = Eigen::Matrix2d::Zero();
    sqrt_information(0, 0) = 1.0 / options_.brightness_prior_sigma_a;
    sqrt_information(1, 1) = 1.0 / options_.brightness_prior_sigma_b;
    problem.AddResidualBlock(
        std::make_unique<ceres::NormalPrior>(
            sqrt_information, Eigen::Vector2d(out.brightness[k][0], out.brightness[k][1])),
        nullptr, {out.brightness[k].data()});
  }
  AddScaleGauge(&out);
  if (options_.marginalize && window.prior != nullptr) AddPrior(window, &out);

  // eq. 5's sigma_I: tracking's estimate where weighting.intensity_noise is estimated.
  WeightingOptions weighting = options_.weighting;
  weighting.sigma_intensity = IntensityNoiseSigma(weighting, window.intensity_noise_sigma);
  ceres::LossFunction* loss = nullptr;
  if (std::unique_ptr<ceres::LossFunction> made = MakeLossFunction(weighting)) {
    loss = problem.AddLossFunction(std::move(made));
  }
  ceres::LossFunction* loss_inside = loss_in_problem_ ? nullptr : loss;
  ceres::LossFunction* loss_outside = loss_in_problem_ ? loss : nullptr;
  // The inverse-depth priors' own loss (idepth_prior_loss, in sigmas of the prior).
  WeightingOptions prior_weighting;
  prior_weighting.robust_loss = options_.idepth_prior_loss;
  prior_weighting.robust_threshold = options_.idepth_prior_loss_threshold;
  ceres::LossFunction* prior_loss = nullptr;
  if (std::unique_ptr<ceres::LossFunction> made = MakeLossFunction(prior_weighting)) {
    prior_loss = problem.AddLossFunction(std::move(made));
  }
  const bool photometric = UsesPhotometric(weighting.policy);
  const bool lines = options_.lines && UsesLines(weighting.policy);

  std::vector<SE3> world_poses(n);
  for (int k = 0; k < n; ++k) world_poses[k] = PoseFromParameters(out.poses[k].data());
  auto position_of = [&](int id) {
    for (int k = 0; k < n; ++k) {
      if (keyframe(k).id == id) return k;
    }
    return -1;
  };

  // The blocks of every point, collected before any inverse-depth block is added: the outlier
  // threshold is a statistic of the whole window, and a point with too few targets is left out
  // entirely.
  struct PendingPhotometric {
    int target;
    std::vector<HostPixel> pattern;
    double energy;  // mean squared whitened row at the input (0 when not computed)
  };
  struct PendingLine {
    int target;
    Eigen::Vector3d line;
    double sqrt_info;
  };
  struct PendingPoint {
    WindowedBAProblemPoint selected;
    std::vector<PendingPhotometric> photometric;
    std::vector<PendingLine> lines;
  };
  const bool outlier_test = photometric && options_.outlier_energy_factor > 0.0;
  std::vector<PendingPoint> pending_points;
  pending_points.reserve(out.points.size());
  std::vector<double> energies;
  for (const WindowedBAProblemPoint& selected : out.points) {
    const int host = selected.host;
    const WindowedBAKeyframe& host_keyframe = keyframe(host);
    const WindowedBAPoint& point = host_keyframe.points[selected.point_index];
    PendingPoint pending_point{selected, {}, {}};
    const double weight_idepth_var = options_.depth_variance_in_weights ? point.idepth_var : 0.0;
    for (int target = 0; target < n && photometric; ++target) {
      if (target == host) continue;
      const SE3 target_from_host = world_poses[target] * world_poses[host].Inverse();
      PendingPhotometric pending{target, {}, 0.0};
      for (int p = 0; p < (dso8 ? 8 : 1); ++p) {
        // Added per coordinate: GCC 12 at -O3 read an Eigen comma-initialised offset here
        // uninitialised (docs/windowed_ba.md, "The pattern fix").
        HostPixel pixel;
        pixel.pixel_in_host.x() = point.pixel.x() + (dso8 ? kDso8Pattern[p][0] : 0.0);
        pixel.pixel_in_host.y() = point.pixel.y() + (dso8 ? kDso8Pattern[p][1] : 0.0);
        pixel.intensity_host = host_keyframe.pyramid->SampleIntensity(0, pixel.pixel_in_host.x(),
                                                                      pixel.pixel_in_host.y());
        // eq. 5 at the linearisation point; 0 where the row's reprojection is not samplable.
        pixel.sqrt_info =
            PhotometricSqrtInfo(weighting, camera, *keyframe(target).pyramid, 0, target_from_host,
                                pixel.pixel_in_host, point.idepth, weight_idepth_var);
        if (pixel.sqrt_info > 0.0) pending.pattern.push_back(pixel);
      }
      // A target where part of the pattern falls outside is left out: the rows would switch
      // on and off as the estimate moves.
      if (static_cast<int>(pending.pattern.size()) != (dso8 ? 8 : 1)) continue;
      if (outlier_test) {
        pending.energy = MeanRowEnergy(*keyframe(target).pyramid, camera, pending.pattern,
                                       out.poses[host], out.poses[target], point.idepth,
                                       out.brightness[host], out.brightness[target]);
        energies.push_back(pending.energy);
      }
      pending_point.photometric.push_back(std::move(pending));
    }
    if (lines && point.edge_id >= 0) {
      for (const WindowedBALineObservation& observation : host_keyframe.line_observations) {
        if (observation.edge_id != point.edge_id) continue;
        const int target = position_of(observation.target_id);
        if (target < 0 || target == host) continue;
        const SE3 target_from_host = world_poses[target] * world_poses[host].Inverse();
        Eigen::Vector2d pixel_in_target;
        if (!Reproject(camera, target_from_host, point.pixel, point.idepth, &pixel_in_target) ||
            !camera.IsInside(pixel_in_target, 0.0)) {
          continue;
        }
        const double sqrt_info =
            LineSqrtInfo(weighting, camera, target_from_host, point.pixel, point.idepth,
                         weight_idepth_var, observation.line_in_target);  // eq. 6
        if (sqrt_info > 0.0) {
          pending_point.lines.push_back({target, observation.line_in_target.line, sqrt_info});
        }
      }
    }
    pending_points.push_back(std::move(pending_point));
  }

  // DSO's outlier test (Engel et al. PAMI 2018, Sec. 3.3) relative to the window: a target whose
  // energy exceeds factor^2 times the window's median (an occlusion, a wrong depth) is left out;
  // relative, so that it does not move with the image's contrast.
  double energy_threshold = std::numeric_limits<double>::infinity();
  if (outlier_test && !energies.empty()) {
    std::nth_element(energies.begin(), energies.begin() + energies.size() / 2, energies.end());
    energy_threshold = options_.outlier_energy_factor * options_.outlier_energy_factor *
                       energies[energies.size() / 2];
  }

  std::vector<WindowedBAProblemPoint> kept_points;
  for (PendingPoint& pending_point : pending_points) {
    std::vector<PendingPhotometric>& pending_photometric = pending_point.photometric;
    const auto outliers =
        std::remove_if(pending_photometric.begin(), pending_photometric.end(),
                       [&](const PendingPhotometric& p) { return p.energy > energy_threshold; });
    out.num_outlier_targets += static_cast<int>(pending_photometric.end() - outliers);
    pending_photometric.erase(outliers, pending_photometric.end());
    const std::vector<PendingLine>& pending_lines = pending_point.lines;
    const int targets = static_cast<int>(pending_photometric.size() + pending_lines.size());
    if (targets < options_.min_targets) continue;
    const WindowedBAProblemPoint& selected = pending_point.selected;
    const int host = selected.host;
    const WindowedBAPoint& point = keyframe(host).points[selected.point_index];
    out.idepths.push_back(point.idepth);
    double* idepth = &out.idepths.back();
    problem.AddParameterBlock(idepth, 1);
    problem.SetParameterBlockEliminated(idepth);
    const bool prior_counts_twice =
        n > 1 && host == n - 1 &&
        options_.newest_keyframe_points == NewestKeyframePoints::kHostNoPrior;
    if (options_.idepth_prior_scale > 0.0 && !prior_counts_twice) {
      const double sigma = options_.idepth_prior_scale * std::sqrt(point.idepth_var);
      const int block = problem.AddResidualBlock(
          std::make_unique<ceres::NormalPrior>(ceres::Matrix::Constant(1, 1, 1.0 / sigma),
                                               ceres::Vector::Constant(1, point.idepth)),
          prior_loss, {idepth});
      if (host == 0) out.oldest_host_blocks.push_back(block);
    }
    kept_points.push_back(selected);
    for (PendingPhotometric& pending : pending_photometric) {
      out.num_photometric_rows += static_cast<int>(pending.pattern.size());
      ++out.num_photometric_blocks;
      const int block = problem.AddResidualBlock(
          std::unique_ptr<ceres::CostFunction>(HostTargetPhotometricResidual::Create(
              *keyframe(pending.target).pyramid, 0, camera, std::move(pending.pattern), loss_inside,
              options_.interpolation)),
          loss_outside,
          {out.poses[host].data(), out.poses[pending.target].data(), idepth,
           out.brightness[host].data(), out.brightness[pending.target].data()});
      if (host == 0) out.oldest_host_blocks.push_back(block);
    }
    for (const PendingLine& pending : pending_lines) {
      ++out.num_line_rows;
      const int block = problem.AddResidualBlock(
          std::unique_ptr<ceres::CostFunction>(HostTargetPointToLineResidual::Create(
              camera, point.pixel, pending.line, pending.sqrt_info, loss_inside)),
          loss_outside, {out.poses[host].data(), out.poses[pending.target].data(), idepth});
      if (host == 0) out.oldest_host_blocks.push_back(block);
    }
  }
  out.points = std::move(kept_points);
  return out;
}

}  // namespace

std::string WindowedBAOptions::Check() const {
  const auto registry = WindowedBAProblemBuilderRegistry();
  if (registry.count(problem_builder) == 0) {
    return "problem_builder '" + problem_builder + "' unknown; known: " + RegistryNames(registry);
  }
  if (window < 2) return "window must be >= 2";
  if (max_points < 1) return "max_points must be >= 1";
  if (!(min_gradient >= 0.0) || !std::isfinite(min_gradient)) return "min_gradient must be >= 0";
  if (min_targets < 1) return "min_targets must be >= 1";
  if (!(outlier_energy_factor >= 0.0) || !std::isfinite(outlier_energy_factor)) {
    return "outlier_energy_factor must be >= 0 and finite";
  }
  if (!(idepth_prior_scale >= 0.0) || !std::isfinite(idepth_prior_scale)) {
    return "idepth_prior_scale must be >= 0 and finite";
  }
  if (!(idepth_prior_loss_threshold > 0.0) || !std::isfinite(idepth_prior_loss_threshold)) {
    return "idepth_prior_loss_threshold must be positive and finite";
  }
  if (!(brightness_prior_sigma_a > 0.0) || !(brightness_prior_sigma_b > 0.0) ||
      !std::isfinite(brightness_prior_sigma_a) || !std::isfinite(brightness_prior_sigma_b)) {
    return "brightness_prior_sigma_a and brightness_prior_sigma_b must be positive and finite";
  }
  if (!(baseline_prior_sigma_ratio > 0.0) || !std::isfinite(baseline_prior_sigma_ratio)) {
    return "baseline_prior_sigma_ratio must be positive and finite";
  }
  if (leaving == LeavingKeyframe::kSpread && marginalize) {
    return "leaving: spread needs marginalize false (the prior marginalises the oldest keyframe)";
  }
  if (!(leaving_min_visible >= 0.0 && leaving_min_visible <= 1.0)) {
    return "leaving_min_visible must be in [0, 1]";
  }
  if (max_iterations < 0) return "max_iterations must be >= 0";
  if (!(function_tolerance >= 0.0)) return "function_tolerance must be >= 0";
  if (num_threads < 1) return "num_threads must be >= 1";
  if (max_queue < 1) return "max_queue must be >= 1";
  const std::string weighting_error = weighting.Check();
  if (!weighting_error.empty()) return "weighting: " + weighting_error;
  // sigma_I comes from tracking (WindowedBAWindow::intensity_noise_sigma); the line noise scale
  // is a tracked frame's, which a window does not have.
  if (weighting.line_noise != NoiseSource::kFixed) {
    return "weighting: line_noise must be fixed (estimated is tracking's)";
  }
  // The window's point-to-line rows are per pixel (eq. 6); one shared error per edge is
  // tracking's only, and accepting it here would change nothing.
  if (weighting.line_error_model != LineErrorModel::kPerPixel) {
    return "weighting: line_error_model must be per_pixel (shared_per_edge is tracking's)";
  }
  return "";
}

std::map<std::string, WindowedBAProblemBuilderFactory> WindowedBAProblemBuilderRegistry() {
  std::map<std::string, WindowedBAProblemBuilderFactory> registry;
  registry["windowed_ba"] = [](const WindowedBAOptions& options) {
    return std::make_unique<PhotometricLineWindowBuilder>(options, /*loss_in_problem=*/false);
  };
  registry["windowed_ba_ceres_loss"] = [](const WindowedBAOptions& options) {
    return std::make_unique<PhotometricLineWindowBuilder>(options, /*loss_in_problem=*/true);
  };
  return registry;
}

std::unique_ptr<WindowedBAProblemBuilder> MakeWindowedBAProblemBuilder(
    const std::string& name, const WindowedBAOptions& options) {
  return FindInRegistry(WindowedBAProblemBuilderRegistry(), name,
                        "windowed BA problem builder")(options);
}

}  // namespace pldvo
