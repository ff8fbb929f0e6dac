#include "experiments/evaluation/edge_ba_simulation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include "core/random_draws.h"
#include "core/statistics.h"

namespace pldvo {
namespace {

// Clips the parameter interval [s0, s1] of a segment to where a function that is linear along
// it, with values value_a and value_b at its ends, is >= 0. False when nothing is left.
bool ClipHalfSpace(double value_a, double value_b, double* s0, double* s1) {
  // value(s) = value_a + s (value_b - value_a) must be >= 0.
  if (value_a < 0.0 && value_b < 0.0) return false;
  if (value_a >= 0.0 && value_b >= 0.0) return true;
  const double s = value_a / (value_a - value_b);
  if (value_a < 0.0) {
    *s0 = std::max(*s0, s);
  } else {
    *s1 = std::min(*s1, s);
  }
  return *s0 < *s1;
}

Eigen::Vector3d CameraCenter(const SE3& cam_from_world) {
  return -(cam_from_world.rotation().inverse() * cam_from_world.translation());
}

Eigen::Vector3d RandomVector(std::mt19937_64* rng, double sigma) {
  std::normal_distribution<double> normal(0.0, sigma);
  return DrawVector3(normal, *rng);
}

double Rms(double sum_sq, int count) { return count > 0 ? std::sqrt(sum_sq / count) : 0.0; }

}  // namespace

EdgeBASimulation SimulateEdgeBAWindow(const PinholeCamera& camera,
                                      const std::vector<SE3>& world_from_cam,
                                      const std::vector<Eigen::Vector3d>& segments_start,
                                      const std::vector<Eigen::Vector3d>& segments_end,
                                      const EdgeBASimulationOptions& options) {
  if (segments_start.size() != segments_end.size() || world_from_cam.empty() ||
      options.pixels_per_observation < 2) {
    throw std::invalid_argument(std::string(__FILE__) +
                                ": SimulateEdgeBAWindow: segment lists differ in size, no "
                                "keyframes, or fewer than 2 pixels per observation");
  }
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> pixel_noise(0.0, options.pixel_sigma);
  EdgeBASimulation simulation;
  simulation.window.camera = camera;
  simulation.start_true = segments_start;
  simulation.end_true = segments_end;
  const int num_keyframes = static_cast<int>(world_from_cam.size());
  for (int k = 0; k < num_keyframes; ++k) {
    const SE3 cam_from_world = world_from_cam[k].Inverse();
    simulation.cam_from_world_true.push_back(cam_from_world);
    EdgeBAKeyframe keyframe;
    keyframe.id = k;
    for (size_t i = 0; i < segments_start.size(); ++i) {
      const Eigen::Vector3d a = cam_from_world * segments_start[i];
      const Eigen::Vector3d b = cam_from_world * segments_end[i];
      double s0 = 0.0, s1 = 1.0;
      if (!ClipHalfSpace(a.z() - options.min_depth, b.z() - options.min_depth, &s0, &s1)) continue;
      Eigen::Vector2d p = camera.Project(a + s0 * (b - a));
      Eigen::Vector2d q = camera.Project(a + s1 * (b - a));
      // Clip the projected segment to the image shrunk by 2 px.
      double t0 = 0.0, t1 = 1.0;
      const double lo = 2.0;
      const double hi[2] = {camera.width - 3.0, camera.height - 3.0};
      bool inside = true;
      for (int axis = 0; axis < 2 && inside; ++axis) {
        inside = ClipHalfSpace(p(axis) - lo, q(axis) - lo, &t0, &t1) &&
                 ClipHalfSpace(hi[axis] - p(axis), hi[axis] - q(axis), &t0, &t1);
      }
      if (!inside) continue;
      const Eigen::Vector2d p_in = p + t0 * (q - p);
      const Eigen::Vector2d q_in = p + t1 * (q - p);
      if ((q_in - p_in).norm() < options.min_length_px) continue;
      // Pixels evenly along the visible 3D part (perspective-correct spacing does not matter
      // for a line; even in the image is what an edge tracer gives).
      EdgeBAObservation observation;
      observation.line_id = static_cast<int>(i);
      observation.line_2d_id = static_cast<int>(keyframe.observations.size());
      observation.sigma_px = options.pixel_sigma > 0.0 ? options.pixel_sigma : 0.0;
      const int n = options.pixels_per_observation;
      for (int j = 0; j < n; ++j) {
        const double s = static_cast<double>(j) / (n - 1);
        observation.pixels.push_back(p_in + s * (q_in - p_in) + DrawVector2(pixel_noise, rng));
      }
      keyframe.observations.push_back(std::move(observation));
    }
    // Noisy initial pose: the oldest exact; the second keeps its distance to the oldest.
    SE3 noisy = cam_from_world;
    if (k > 0) {
      Vector6d twist;
      twist.head<3>() = RandomVector(&rng, options.pose_sigma_m);
      twist.tail<3>() = RandomVector(&rng, options.pose_sigma_rad);
      noisy = SE3::Exp(twist) * cam_from_world;
      if (k == 1) {
        const Eigen::Vector3d center0 = CameraCenter(simulation.cam_from_world_true[0]);
        const double baseline = (CameraCenter(cam_from_world) - center0).norm();
        const Eigen::Vector3d offset = CameraCenter(noisy) - center0;
        const Eigen::Vector3d center = center0 + offset * (baseline / offset.norm());
        noisy = SE3(noisy.rotation(), -(noisy.rotation() * center));
      }
    }
    keyframe.cam_from_world = noisy;
    simulation.window.keyframes.push_back(std::move(keyframe));
  }
  if (options.provide_initial_lines) {
    for (size_t i = 0; i < segments_start.size(); ++i) {
      const Eigen::Vector3d direction = (segments_end[i] - segments_start[i]).normalized();
      const Eigen::Vector3d midpoint = 0.5 * (segments_start[i] + segments_end[i]);
      Eigen::Vector3d shift = RandomVector(&rng, options.line_sigma_m);
      shift -= direction * direction.dot(shift);
      const Eigen::Vector3d rotation = RandomVector(&rng, options.line_sigma_rad);
      EdgeBALine line;
      line.id = static_cast<int>(i);
      line.point_in_world = midpoint + shift;
      line.direction_in_world = ExpSO3(rotation) * direction;
      simulation.window.lines.push_back(line);
    }
  }
  return simulation;
}

EdgeBAScene MakeRandomLineScene(int num_lines, int num_keyframes, double spacing_m,
                                std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> length(0.5, 1.5);
  EdgeBAScene scene;
  for (int i = 0; i < num_lines; ++i) {
    const Eigen::Vector3d u = DrawVector3(unit, rng);
    const Eigen::Vector3d midpoint(2.0 * u.x(), 1.5 * u.y(), 4.5 + 1.5 * u.z());
    Eigen::Vector3d direction;
    do {
      direction = DrawVector3(unit, rng);
    } while (direction.norm() > 1.0 || direction.norm() < 0.1);  // uniform on the sphere
    direction.normalize();
    const double half = 0.5 * length(rng);
    scene.start.push_back(midpoint - half * direction);
    scene.end.push_back(midpoint + half * direction);
  }
  const double max_angle = 2.0 * M_PI / 180.0;
  for (int k = 0; k < num_keyframes; ++k) {
    const Eigen::Vector3d center =
        Eigen::Vector3d(spacing_m * (k - 0.5 * (num_keyframes - 1)), 0.0, 0.0) +
        0.02 * DrawVector3(unit, rng);
    const Eigen::Vector3d rotation = max_angle * DrawVector3(unit, rng);
    scene.world_from_cam.push_back(SE3(ExpSO3(rotation), center));
  }
  return scene;
}

EdgeBAErrors ComputeEdgeBAErrors(const EdgeBASimulation& simulation,
                                 const std::vector<EdgeBAResultKeyframe>& keyframes,
                                 const std::vector<EdgeBALine>& lines) {
  EdgeBAErrors errors;
  double position_sq = 0.0, rotation_sq = 0.0;
  int num_poses = 0;
  for (const EdgeBAResultKeyframe& keyframe : keyframes) {
    if (keyframe.id <= 0 ||
        keyframe.id >= static_cast<int>(simulation.cam_from_world_true.size())) {
      continue;  // the oldest is the gauge
    }
    const SE3& truth = simulation.cam_from_world_true[keyframe.id];
    position_sq += (CameraCenter(keyframe.cam_from_world) - CameraCenter(truth)).squaredNorm();
    const double angle =
        LogSO3(keyframe.cam_from_world.rotation_matrix() * truth.rotation_matrix().transpose())
            .norm();
    rotation_sq += angle * angle;
    ++num_poses;
  }
  errors.position_rmse_m = Rms(position_sq, num_poses);
  errors.rotation_rmse_deg = Rms(rotation_sq, num_poses) * 180.0 / M_PI;
  double distance_sq = 0.0, angle_sq = 0.0;
  std::vector<double> distances, angles;
  for (const EdgeBALine& line : lines) {
    if (line.id < 0 || line.id >= static_cast<int>(simulation.start_true.size())) continue;
    const Eigen::Vector3d direction = line.direction_in_world.normalized();
    double line_distance_sq = 0.0;
    for (const Eigen::Vector3d& end :
         {simulation.start_true[line.id], simulation.end_true[line.id]}) {
      const Eigen::Vector3d offset = end - line.point_in_world;
      line_distance_sq += 0.5 * (offset - direction * direction.dot(offset)).squaredNorm();
    }
    distance_sq += line_distance_sq;
    distances.push_back(std::sqrt(line_distance_sq));
    const Eigen::Vector3d truth =
        (simulation.end_true[line.id] - simulation.start_true[line.id]).normalized();
    const double angle = std::acos(std::min(1.0, std::abs(direction.dot(truth))));
    angle_sq += angle * angle;
    angles.push_back(angle);
    ++errors.num_lines;
  }
  errors.line_distance_median_m = Median(distances);
  errors.line_angle_median_deg = Median(angles) * 180.0 / M_PI;
  errors.line_distance_rmse_m = Rms(distance_sq, errors.num_lines);
  errors.line_angle_rmse_deg = Rms(angle_sq, errors.num_lines) * 180.0 / M_PI;
  return errors;
}

EdgeBAErrors InitialEdgeBAErrors(const EdgeBASimulation& simulation,
                                 const std::vector<int>& line_ids) {
  std::vector<EdgeBAResultKeyframe> keyframes;
  for (const EdgeBAKeyframe& keyframe : simulation.window.keyframes) {
    EdgeBAResultKeyframe k;
    k.id = keyframe.id;
    k.cam_from_world = keyframe.cam_from_world;
    keyframes.push_back(k);
  }
  std::map<int, const EdgeBALine*> by_id;
  for (const EdgeBALine& line : simulation.window.lines) by_id[line.id] = &line;
  std::vector<EdgeBALine> lines;
  for (int id : line_ids) {
    const auto it = by_id.find(id);
    if (it != by_id.end()) lines.push_back(*it->second);
  }
  return ComputeEdgeBAErrors(simulation, keyframes, lines);
}

}  // namespace pldvo
