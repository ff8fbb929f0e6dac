#include "backend/edge_ba/edge_ba_problem_builder.h"

#include <ceres/line_manifold.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

#include "backend/edge_ba/edge_ba_line_triangulation.h"
#include "backend/edge_ba/edge_ba_motion_prior.h"
#include "residuals/baseline_prior_residual.h"
#include "residuals/covariance_models.h"
#include "residuals/line_observation_residual.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

// A pose needs 6 independent constraints; each line observation gives 2 (the projected line's
// offset and angle), so fewer than 3 lines cannot determine it.
constexpr int kMinLinesPerPose = 3;
// Below this fraction of the largest baseline, the two oldest keyframes' baseline is too short to
// carry the scale prior.
constexpr double kShortBaselineRatio = 1e-3;

Eigen::Vector3d CameraCenter(const SE3& cam_from_world) {
  return -(cam_from_world.rotation().inverse() * cam_from_world.translation());
}

std::unique_ptr<ceres::LossFunction> MakeLoss(const EdgeBAOptions& options) {
  switch (options.robust_loss) {
    case RobustLossKind::kNone:
      return nullptr;
    case RobustLossKind::kHuber:
      return std::make_unique<ceres::HuberLoss>(options.robust_threshold);
    case RobustLossKind::kCauchy:
      return std::make_unique<ceres::CauchyLoss>(options.robust_threshold);
  }
  return nullptr;
}

// Evenly spaced subset of at most `max_count` pixels (0 = all), first and last kept.
std::vector<Eigen::Vector2d> Subsample(const std::vector<Eigen::Vector2d>& pixels, int max_count) {
  const int n = static_cast<int>(pixels.size());
  if (max_count == 0 || n <= max_count) return pixels;
  std::vector<Eigen::Vector2d> subset;
  subset.reserve(max_count);
  for (int i = 0; i < max_count; ++i) {
    subset.push_back(pixels[static_cast<size_t>(
        std::lround(static_cast<double>(i) * (n - 1) / static_cast<double>(max_count - 1)))]);
  }
  return subset;
}

struct LineObservations {
  std::vector<std::pair<int, int>> observations;  // (window position, observation index)
  std::set<int> keyframes;                        // window positions
};

}  // namespace

std::vector<double*> EdgeBAProblem::VariableLineBlocks() {
  std::vector<double*> blocks;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (line_status[i] == EdgeBALineStatus::kOptimized) blocks.push_back(lines[i].data());
  }
  return blocks;
}

std::vector<double*> EdgeBAProblem::VariablePoseBlocks() {
  std::vector<double*> blocks;
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!pose_fixed[i]) blocks.push_back(poses[i].data());
  }
  return blocks;
}

int EdgeBAProblem::NumVariableTangentParameters() const {
  int count = 0;
  for (bool fixed : pose_fixed) count += fixed ? 0 : kPoseTangentSize;
  for (EdgeBALineStatus status : line_status) {
    count += status == EdgeBALineStatus::kOptimized ? kLineTangentSize : 0;
  }
  return count;
}

EdgeBAProblemBuilder::EdgeBAProblemBuilder(const EdgeBAOptions& options) : options_(options) {
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument(std::string(__FILE__) + ": EdgeBAProblemBuilder: " + error);
  }
}

EdgeBAProblem EdgeBAProblemBuilder::Build(const EdgeBAWindow& window) const {
  CheckEdgeBAWindow(window);
  const PinholeCamera& camera = window.camera;
  EdgeBAProblem out;
  const int num_keyframes = static_cast<int>(window.keyframes.size());
  const int first = std::max(0, num_keyframes - options_.window);
  for (int k = first; k < num_keyframes; ++k) out.keyframe_indices.push_back(k);
  const int num_window = static_cast<int>(out.keyframe_indices.size());
  out.poses.resize(num_window);
  std::vector<SE3> cam_from_world(num_window);
  for (int w = 0; w < num_window; ++w) {
    cam_from_world[w] = window.keyframes[out.keyframe_indices[w]].cam_from_world;
    PoseToParameters(cam_from_world[w], out.poses[w].data());
  }

  // Observations per line id inside the window.
  std::map<int, LineObservations> observed;
  for (int w = 0; w < num_window; ++w) {
    const EdgeBAKeyframe& keyframe = window.keyframes[out.keyframe_indices[w]];
    for (int i = 0; i < static_cast<int>(keyframe.observations.size()); ++i) {
      LineObservations& line = observed[keyframe.observations[i].line_id];
      line.observations.emplace_back(w, i);
      line.keyframes.insert(w);
    }
  }
  std::map<int, const EdgeBALine*> listed;
  for (const EdgeBALine& line : window.lines) listed[line.id] = &line;
  std::set<int> all_ids;
  for (const auto& [id, unused] : observed) all_ids.insert(id);
  for (const auto& [id, unused] : listed) all_ids.insert(id);

  const double min_plane_angle = options_.min_plane_angle_deg * M_PI / 180.0;
  out.line_ids.assign(all_ids.begin(), all_ids.end());
  out.lines.resize(out.line_ids.size());
  out.line_status.assign(out.line_ids.size(), EdgeBALineStatus::kDropped);
  for (size_t i = 0; i < out.line_ids.size(); ++i) {
    const int id = out.line_ids[i];
    const auto listed_it = listed.find(id);
    const EdgeBALine* initial = listed_it != listed.end() ? listed_it->second : nullptr;
    Eigen::Vector3d point = initial != nullptr ? initial->point_in_world : Eigen::Vector3d::Zero();
    Eigen::Vector3d direction =
        initial != nullptr ? initial->direction_in_world.normalized() : Eigen::Vector3d::UnitX();
    const auto observed_it = observed.find(id);
    EdgeBALineStatus status = EdgeBALineStatus::kDropped;
    if (observed_it != observed.end()) {
      const LineObservations& obs = observed_it->second;
      if (initial != nullptr && initial->anchored &&
          options_.lines_leaving_window == EdgeBALeavingLines::kFixed) {
        status = EdgeBALineStatus::kFixed;
      } else if (static_cast<int>(obs.keyframes.size()) >= options_.min_observing_keyframes) {
        std::vector<WorldPlane> planes;
        for (const auto& [w, index] : obs.observations) {
          WorldPlane plane;
          const EdgeBAKeyframe& keyframe = window.keyframes[out.keyframe_indices[w]];
          if (BackProjectedPlane(camera, cam_from_world[w], keyframe.observations[index].pixels,
                                 &plane)) {
            planes.push_back(plane);
          }
        }
        const bool well_posed = planes.size() >= 2 && LargestPlaneAngle(planes) >= min_plane_angle;
        if (well_posed && (initial != nullptr || IntersectPlanes(planes, &point, &direction))) {
          status = EdgeBALineStatus::kOptimized;
        }
      }
      if (status != EdgeBALineStatus::kDropped) {
        // The projection must be defined in every observing keyframe.
        Eigen::Vector3d image_line;
        Eigen::Vector3d mean_center = Eigen::Vector3d::Zero();
        for (int w : obs.keyframes) {
          if (!ProjectLine(camera, cam_from_world[w], point, direction, &image_line)) {
            status = EdgeBALineStatus::kDropped;
          }
          mean_center += CameraCenter(cam_from_world[w]);
        }
        // Store the point of the line nearest the observing cameras: parameters in metres near
        // the observed edge whatever the world origin (conditioning).
        mean_center /= static_cast<double>(obs.keyframes.size());
        point += direction * direction.dot(mean_center - point);
      }
    }
    out.line_status[i] = status;
    Eigen::Map<Eigen::Vector3d>(out.lines[i].data()) = point;
    Eigen::Map<Eigen::Vector3d>(out.lines[i].data() + 3) = direction;
  }
  std::map<int, int> line_index;
  for (size_t i = 0; i < out.line_ids.size(); ++i) line_index[out.line_ids[i]] = i;

  // Poses: the oldest fixed, poorly observed ones fixed, then the scale gauge.
  out.pose_fixed.assign(num_window, false);
  if (num_window > 0) out.pose_fixed[0] = true;
  for (int w = 0; w < num_window; ++w) {
    std::set<int> usable;
    for (const EdgeBAObservation& o : window.keyframes[out.keyframe_indices[w]].observations) {
      if (out.line_status[line_index[o.line_id]] != EdgeBALineStatus::kDropped) {
        usable.insert(o.line_id);
      }
    }
    if (static_cast<int>(usable.size()) < kMinLinesPerPose) out.pose_fixed[w] = true;
  }
  if (num_window >= 2) {
    if (options_.gauge == EdgeBAGauge::kFirstTwoPoses) {
      out.pose_fixed[1] = true;
    } else if (std::count(out.pose_fixed.begin() + 1, out.pose_fixed.end(), true) == 0) {
      // No second pose is constant, so the scale is free: hold a baseline from the oldest.
      const Eigen::Vector3d center0 = CameraCenter(cam_from_world[0]);
      int farthest = 1;
      double largest = 0.0;
      for (int w = 1; w < num_window; ++w) {
        const double b = (CameraCenter(cam_from_world[w]) - center0).norm();
        if (b > largest) {
          largest = b;
          farthest = w;
        }
      }
      const double next = (CameraCenter(cam_from_world[1]) - center0).norm();
      const int partner = next >= kShortBaselineRatio * largest ? 1 : farthest;
      const double baseline = (CameraCenter(cam_from_world[partner]) - center0).norm();
      if (baseline > 0.0) {
        out.baseline_keyframe_a = 0;
        out.baseline_keyframe_b = partner;
        out.baseline = baseline;
      } else {
        out.pose_fixed[1] = true;  // all centres coincide: no scale to hold
      }
    }
  }

  // Parameter blocks.
  LeastSquaresProblem& problem = out.problem;
  for (int w = 0; w < num_window; ++w) {
    problem.AddParameterBlock(out.poses[w].data(), kPoseAmbientSize,
                              std::make_unique<SE3Manifold>());
    if (out.pose_fixed[w]) problem.SetParameterBlockConstant(out.poses[w].data());
  }
  for (size_t i = 0; i < out.lines.size(); ++i) {
    if (out.line_status[i] == EdgeBALineStatus::kDropped) continue;
    problem.AddParameterBlock(out.lines[i].data(), kLineAmbientSize,
                              std::make_unique<ceres::LineManifold<3>>());
    if (out.line_status[i] == EdgeBALineStatus::kFixed) {
      problem.SetParameterBlockConstant(out.lines[i].data());
    }
  }
  ceres::LossFunction* loss = problem.AddLossFunction(MakeLoss(options_));

  // Residual blocks: one per (keyframe, line) observation.
  for (int w = 0; w < num_window; ++w) {
    const EdgeBAKeyframe& keyframe = window.keyframes[out.keyframe_indices[w]];
    for (const EdgeBAObservation& o : keyframe.observations) {
      const int li = line_index[o.line_id];
      if (out.line_status[li] == EdgeBALineStatus::kDropped) continue;
      if (out.line_status[li] == EdgeBALineStatus::kFixed && out.pose_fixed[w]) continue;
      const double* line = out.lines[li].data();
      Eigen::Vector3d image_line;
      ProjectLine(camera, cam_from_world[w], Eigen::Vector3d(line[0], line[1], line[2]),
                  Eigen::Vector3d(line[3], line[4], line[5]), &image_line);
      const double sigma_px = o.sigma_px > 0.0 ? o.sigma_px : options_.default_sigma_px;
      Eigen::Matrix3d pixel_cov = Eigen::Matrix3d::Zero();
      pixel_cov(0, 0) = pixel_cov(1, 1) = sigma_px * sigma_px;
      std::vector<LineObservationPixel> pixels;
      for (const Eigen::Vector2d& pixel :
           Subsample(o.pixels, options_.max_pixels_per_observation)) {
        LineObservationPixel p;
        p.pixel = pixel;
        // The projected line is a function of the variables (no covariance of its own).
        p.sqrt_info = 1.0 / std::sqrt(PointToLineVariance(image_line, Eigen::Matrix3d::Zero(),
                                                          pixel, pixel_cov));
        pixels.push_back(p);
      }
      out.num_pixel_residuals += static_cast<int>(pixels.size());
      const std::vector<double*> blocks = {out.poses[w].data(), out.lines[li].data()};
      if (options_.batch_pixels) {
        problem.AddResidualBlock(
            std::unique_ptr<ceres::CostFunction>(
                LineObservationResidual::Create(camera, std::move(pixels), loss)),
            nullptr, blocks);
      } else {
        for (const LineObservationPixel& pixel : pixels) {
          problem.AddResidualBlock(std::unique_ptr<ceres::CostFunction>(
                                       LineObservationResidual::Create(camera, {pixel}, nullptr)),
                                   loss, blocks);
        }
      }
    }
  }
  if (options_.motion_prior) {
    // Window keyframes are consecutive in `window.keyframes`, so w - 1 is the previous one.
    const double sigma_r = options_.motion_prior_rotation_deg * M_PI / 180.0;
    for (int w = 1; w < num_window; ++w) {
      const EdgeBAKeyframe& keyframe = window.keyframes[out.keyframe_indices[w]];
      if (!keyframe.has_motion_prior || (out.pose_fixed[w - 1] && out.pose_fixed[w])) continue;
      // A floor for keyframes at (nearly) the same position: 1e-6 of the unit scale.
      const double sigma_t = std::max(options_.motion_prior_translation_ratio *
                                          keyframe.previous_from_this.translation().norm(),
                                      1e-6);
      problem.AddResidualBlock(std::unique_ptr<ceres::CostFunction>(EdgeBAMotionPrior::Create(
                                   keyframe.previous_from_this, sigma_t, sigma_r)),
                               nullptr, {out.poses[w - 1].data(), out.poses[w].data()});
      ++out.num_motion_priors;
    }
  }
  if (out.baseline_keyframe_a >= 0) {
    problem.AddResidualBlock(
        std::unique_ptr<ceres::CostFunction>(BaselinePriorResidual::Create(
            out.baseline, options_.baseline_prior_sigma_ratio * out.baseline)),
        nullptr,
        {out.poses[out.baseline_keyframe_a].data(), out.poses[out.baseline_keyframe_b].data()});
  }
  return out;
}

}  // namespace pldvo
