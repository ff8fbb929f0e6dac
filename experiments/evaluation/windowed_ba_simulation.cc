#include "experiments/evaluation/windowed_ba_simulation.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>

#include "residuals/covariance_models.h"

namespace pldvo {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// A plane n . p = c (world frame), optionally bounded to |p - centre| along its two in-plane
// axes, with value-noise texture.
struct TexturedPlane {
  Eigen::Vector3d normal;
  double offset;
  Eigen::Vector3d axis_u, axis_v;  // in-plane, for texture coordinates and bounds
  Eigen::Vector3d centre;
  double half_u = 1e9, half_v = 1e9;
  std::uint32_t seed;
  bool painted_lines = false;
  double contrast = 110.0;  // amplitude of the value noise, gray levels
};

// 3D lines painted on the back wall as step edges, and their segments (edge ids = indices).
struct PaintedLine {
  Eigen::Vector3d start, end;
  double step;  // gray levels added on the positive side
};

double Hash(std::uint32_t seed, int i, int j) {
  std::uint32_t h = seed * 0x9E3779B1u ^ static_cast<std::uint32_t>(i) * 0x85EBCA77u ^
                    static_cast<std::uint32_t>(j) * 0xC2B2AE3Du;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  h *= 0x297A2D39u;
  h ^= h >> 15;
  return (h & 0xFFFFFF) / static_cast<double>(0xFFFFFF);
}

// Smooth value noise in [0, 1] of cells `cell` metres.
double ValueNoise(std::uint32_t seed, double u, double v, double cell) {
  const double x = u / cell, y = v / cell;
  const int i = static_cast<int>(std::floor(x)), j = static_cast<int>(std::floor(y));
  double fx = x - i, fy = y - j;
  fx = fx * fx * (3.0 - 2.0 * fx);
  fy = fy * fy * (3.0 - 2.0 * fy);
  const double a = Hash(seed, i, j), b = Hash(seed, i + 1, j);
  const double c = Hash(seed, i, j + 1), d = Hash(seed, i + 1, j + 1);
  return (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
}

struct Scene {
  std::vector<TexturedPlane> planes;
  std::vector<PaintedLine> lines;

  // Nearest hit along origin + t direction: t, plane index; false when none.
  bool Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* t_hit,
            int* plane_hit) const {
    *t_hit = 1e18;
    *plane_hit = -1;
    for (size_t i = 0; i < planes.size(); ++i) {
      const TexturedPlane& plane = planes[i];
      const double denominator = plane.normal.dot(direction);
      if (std::abs(denominator) < 1e-12) continue;
      const double t = (plane.offset - plane.normal.dot(origin)) / denominator;
      if (!(t > 1e-6) || t >= *t_hit) continue;
      const Eigen::Vector3d p = origin + t * direction - plane.centre;
      if (std::abs(p.dot(plane.axis_u)) > plane.half_u ||
          std::abs(p.dot(plane.axis_v)) > plane.half_v) {
        continue;
      }
      *t_hit = t;
      *plane_hit = static_cast<int>(i);
    }
    return *plane_hit >= 0;
  }

  double Albedo(int plane_index, const Eigen::Vector3d& point) const {
    const TexturedPlane& plane = planes[plane_index];
    const Eigen::Vector3d local = point - plane.centre;
    double intensity = 70.0 + 110.0 * ValueNoise(plane.seed, local.dot(plane.axis_u),
                                                 local.dot(plane.axis_v), 0.05);
    if (plane.painted_lines) {
      for (const PaintedLine& line : lines) {
        // Signed distance in the wall plane to the line, a sharp (4 mm) sigmoid step.
        const Eigen::Vector3d direction = (line.end - line.start).normalized();
        const Eigen::Vector3d side = plane.normal.cross(direction);
        const double s = (point - line.start).dot(side);
        intensity += line.step / (1.0 + std::exp(-s / 0.004));
      }
    }
    return intensity;
  }
};

Scene MakeScene() {
  Scene scene;
  auto plane = [](Eigen::Vector3d normal, Eigen::Vector3d centre, Eigen::Vector3d u,
                  std::uint32_t seed) {
    TexturedPlane p;
    p.normal = normal.normalized();
    p.offset = p.normal.dot(centre);
    p.centre = centre;
    p.axis_u = u.normalized();
    p.axis_v = p.normal.cross(p.axis_u);
    p.seed = seed;
    return p;
  };
  TexturedPlane back = plane({0, 0, 1}, {0, 0, 4.0}, {1, 0, 0}, 11);
  back.painted_lines = true;
  back.contrast = 30.0;  // the painted edges dominate the back wall's gradients
  scene.planes.push_back(back);
  scene.planes.push_back(plane({0, 1, 0}, {0, 1.0, 2.0}, {1, 0, 0}, 12));   // floor
  scene.planes.push_back(plane({1, 0, 0}, {-1.8, 0, 2.0}, {0, 0, 1}, 13));  // left wall
  TexturedPlane panel = plane({0.3, 0, 1}, {0.9, -0.2, 2.6}, {1, 0, -0.3}, 14);
  panel.half_u = 0.35;
  panel.half_v = 0.45;
  scene.planes.push_back(panel);
  const double z = 4.0;
  for (const double x : {-1.2, -0.45, 0.35, 1.5}) {
    scene.lines.push_back({{x, -1.5, z}, {x, 1.0, z}, scene.lines.size() % 2 == 0 ? 40.0 : -40.0});
  }
  for (const double y : {-0.75, 0.3}) {
    scene.lines.push_back({{-1.8, y, z}, {2.5, y, z}, y < 0 ? 35.0 : -35.0});
  }
  return scene;
}

double AngleDeg(const SE3& a, const SE3& b) {
  const Eigen::AngleAxisd angle_axis(a.rotation_matrix() * b.rotation_matrix().transpose());
  return std::abs(angle_axis.angle()) / kDegToRad;
}

}  // namespace

WindowedBASimulation SimulateWindowedBAWindow(const WindowedBASimulationOptions& options) {
  const Scene scene = MakeScene();
  WindowedBASimulation simulation;
  PinholeCamera& camera = simulation.window.camera;
  camera = PinholeCamera{options.width,
                         options.height,
                         options.focal,
                         options.focal,
                         (options.width - 1) / 2.0,
                         (options.height - 1) / 2.0};
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);

  for (int k = 0; k < options.num_keyframes; ++k) {
    const Eigen::Vector3d centre(options.spacing * k, -0.1 * options.spacing * k,
                                 0.25 * options.spacing * k);
    const Eigen::Matrix3d world_from_cam_rotation =
        Eigen::AngleAxisd(options.yaw_step_deg * k * kDegToRad, Eigen::Vector3d::UnitY())
            .toRotationMatrix() *
        Eigen::AngleAxisd(0.3 * k * kDegToRad, Eigen::Vector3d::UnitX()).toRotationMatrix();
    const SE3 world_from_cam(Eigen::Quaterniond(world_from_cam_rotation), centre);
    simulation.true_cam_from_world.push_back(world_from_cam.Inverse());
    AffineBrightness brightness;
    if (k > 0) {
      brightness.a = options.gain_step * (k % 2 == 0 ? 1.0 : -1.0);
      brightness.b = options.bias_step * k;
    }
    simulation.true_brightness.push_back(brightness);
  }

  for (int k = 0; k < options.num_keyframes; ++k) {
    const SE3& cam_from_world = simulation.true_cam_from_world[k];
    const SE3 world_from_cam = cam_from_world.Inverse();
    const Eigen::Matrix3d rotation = world_from_cam.rotation_matrix();
    const Eigen::Vector3d origin = world_from_cam.translation();
    // Render: the mean of 2x2 rays per pixel (anti-aliasing), then the Gaussian pixel response.
    // The idepth and the plane seen come from the pixel centre's ray.
    cv::Mat image(camera.height, camera.width, CV_32F);
    cv::Mat idepth_map(camera.height, camera.width, CV_64F, cv::Scalar(0.0));
    cv::Mat plane_map(camera.height, camera.width, CV_32S, cv::Scalar(-1));
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        double t;
        int hit;
        const Eigen::Vector3d centre_ray = camera.Unproject(Eigen::Vector2d(x, y));
        if (scene.Cast(origin, rotation * centre_ray, &t, &hit)) {
          idepth_map.at<double>(y, x) = 1.0 / t;  // the ray has z = 1: t is the z-depth
          plane_map.at<int>(y, x) = hit;
        }
        double sum = 0.0;
        for (const double dy : {-0.25, 0.25}) {
          for (const double dx : {-0.25, 0.25}) {
            const Eigen::Vector3d ray =
                rotation * camera.Unproject(Eigen::Vector2d(x + dx, y + dy));
            if (scene.Cast(origin, ray, &t, &hit)) sum += scene.Albedo(hit, origin + t * ray);
          }
        }
        image.at<float>(y, x) = static_cast<float>(0.25 * sum);
      }
    }
    // A candidate whose pattern and its blur footprint (7x7 pixels) see one plane: the depth
    // filter does not converge across occlusion boundaries and creases.
    auto on_one_plane = [&](double px, double py) {
      const int cx = static_cast<int>(std::lround(px)), cy = static_cast<int>(std::lround(py));
      const int plane = plane_map.at<int>(cy, cx);
      for (int y = cy - 3; y <= cy + 3; ++y) {
        for (int x = cx - 3; x <= cx + 3; ++x) {
          if (plane_map.at<int>(y, x) != plane) return false;
        }
      }
      return plane >= 0;
    };
    if (options.blur_sigma_px > 0.0) {
      cv::GaussianBlur(image, image, cv::Size(0, 0), options.blur_sigma_px);
    }
    const AffineBrightness& brightness = simulation.true_brightness[k];
    const double gain = std::exp(brightness.a);
    for (int y = 0; y < camera.height; ++y) {
      for (int x = 0; x < camera.width; ++x) {
        float& value = image.at<float>(y, x);
        value = static_cast<float>(gain * value + brightness.b + options.noise_sigma * gauss(rng));
      }
    }
    WindowedBAKeyframe keyframe;
    keyframe.id = k;
    keyframe.pyramid = std::make_shared<const ImagePyramid>(image, 1);
    std::vector<double> true_idepths;
    auto add_point = [&](const Eigen::Vector2d& pixel, double idepth, int edge_id) {
      WindowedBAPoint point;
      point.pixel = pixel;
      point.idepth = idepth * std::max(0.5, 1.0 + options.idepth_relative_sigma * gauss(rng));
      const double sigma = options.idepth_var_relative * idepth;
      point.idepth_var = sigma * sigma;
      point.edge_id = edge_id;
      keyframe.points.push_back(point);
      true_idepths.push_back(idepth);
    };
    // Edge points: every 2 px along each painted line's projection, where the wall is seen; the
    // pixel candidates within 1.5 px of a line are left to them (the edge pixels of the line).
    cv::Mat near_line(camera.height, camera.width, CV_8U, cv::Scalar(0));
    for (size_t i = 0; i < scene.lines.size(); ++i) {
      const PaintedLine& line = scene.lines[i];
      const Eigen::Vector3d a = cam_from_world * line.start, b = cam_from_world * line.end;
      const Eigen::Vector2d pa = camera.Project(a), pb = camera.Project(b);
      const int steps = static_cast<int>((pb - pa).norm() / 2.0);
      for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector3d p_cam = a + (b - a) * (static_cast<double>(s) / std::max(1, steps));
        const Eigen::Vector2d pixel = camera.Project(p_cam);
        if (!camera.IsInside(pixel, 4.0)) continue;
        for (int y = static_cast<int>(pixel.y()) - 1; y <= static_cast<int>(pixel.y()) + 2; ++y) {
          for (int x = static_cast<int>(pixel.x()) - 1; x <= static_cast<int>(pixel.x()) + 2; ++x) {
            near_line.at<unsigned char>(y, x) = 1;
          }
        }
        double t;
        int hit;
        const Eigen::Vector3d ray_in_cam = camera.Unproject(pixel);
        if (!scene.Cast(origin, rotation * ray_in_cam, &t, &hit) || hit != 0 ||
            !on_one_plane(pixel.x(), pixel.y())) {
          continue;
        }
        add_point(pixel, 1.0 / t, static_cast<int>(i));
      }
    }
    // Candidates: pixels with a strong enough gradient.
    for (int y = 4; y < camera.height - 4; ++y) {
      for (int x = 4; x < camera.width - 4; ++x) {
        const double idepth = idepth_map.at<double>(y, x);
        if (!(idepth > 0.0) || near_line.at<unsigned char>(y, x) || !on_one_plane(x, y)) continue;
        const Eigen::Vector3f sample = keyframe.pyramid->Sample(0, x, y);
        if (std::hypot(sample[1], sample[2]) < options.candidate_min_gradient) continue;
        add_point(Eigen::Vector2d(x, y), idepth, -1);
      }
    }
    simulation.true_idepths.push_back(std::move(true_idepths));
    simulation.window.keyframes.push_back(std::move(keyframe));
  }

  // Line observations: each painted line in every other keyframe, from the true geometry.
  for (int h = 0; h < options.num_keyframes; ++h) {
    for (int t = 0; t < options.num_keyframes; ++t) {
      if (t == h) continue;
      const SE3& target = simulation.true_cam_from_world[t];
      for (size_t i = 0; i < scene.lines.size(); ++i) {
        WindowedBALineObservation observation;
        observation.edge_id = static_cast<int>(i);
        observation.target_id = t;
        observation.line_in_target =
            FitLine(camera.Project(target * scene.lines[i].start),
                    camera.Project(target * scene.lines[i].end), options.line_endpoint_sigma_px);
        simulation.window.keyframes[h].line_observations.push_back(observation);
      }
    }
  }

  // Perturbed inputs (the oldest keyframe is the gauge: exact).
  for (int k = 0; k < options.num_keyframes; ++k) {
    WindowedBAKeyframe& keyframe = simulation.window.keyframes[k];
    keyframe.cam_from_world = simulation.true_cam_from_world[k];
    if (k == 0) continue;
    Vector6d twist;
    for (int i = 0; i < 3; ++i) twist[i] = options.translation_sigma * gauss(rng);
    for (int i = 3; i < 6; ++i) twist[i] = options.rotation_sigma_deg * kDegToRad * gauss(rng);
    keyframe.cam_from_world = SE3::Exp(twist) * keyframe.cam_from_world;
  }
  return simulation;
}

WindowedBAErrors EvaluateWindowedBA(const WindowedBASimulation& simulation,
                                    const std::vector<SE3>& cam_from_world,
                                    const std::vector<WindowedBAResultPoint>& points) {
  WindowedBAErrors errors;
  const int n = static_cast<int>(cam_from_world.size());
  const Eigen::Vector3d origin_est = cam_from_world[0].Inverse().translation();
  const Eigen::Vector3d origin_true = simulation.true_cam_from_world[0].Inverse().translation();
  double numerator = 0.0, denominator = 0.0;
  for (int k = 1; k < n; ++k) {
    const Eigen::Vector3d c_est = cam_from_world[k].Inverse().translation() - origin_est;
    const Eigen::Vector3d c_true =
        simulation.true_cam_from_world[k].Inverse().translation() - origin_true;
    numerator += c_true.dot(c_est);
    denominator += c_est.squaredNorm();
  }
  errors.scale = denominator > 0.0 ? numerator / denominator : 1.0;
  double rotation_sq = 0.0, translation_sq = 0.0;
  for (int k = 1; k < n; ++k) {
    const Eigen::Vector3d c_est = cam_from_world[k].Inverse().translation() - origin_est;
    const Eigen::Vector3d c_true =
        simulation.true_cam_from_world[k].Inverse().translation() - origin_true;
    translation_sq += (errors.scale * c_est - c_true).squaredNorm();
    const double angle = AngleDeg(cam_from_world[k], simulation.true_cam_from_world[k]);
    rotation_sq += angle * angle;
  }
  errors.rotation_rms_deg = n > 1 ? std::sqrt(rotation_sq / (n - 1)) : 0.0;
  errors.translation_rms_m = n > 1 ? std::sqrt(translation_sq / (n - 1)) : 0.0;
  double idepth_sq = 0.0;
  std::vector<double> absolute;
  for (const WindowedBAResultPoint& point : points) {
    const double truth = simulation.true_idepths[point.keyframe_id][point.point_index];
    const double relative = (point.idepth / errors.scale - truth) / truth;
    idepth_sq += relative * relative;
    absolute.push_back(std::abs(relative));
  }
  if (!points.empty()) {
    errors.idepth_relative_rms = std::sqrt(idepth_sq / points.size());
    std::nth_element(absolute.begin(), absolute.begin() + absolute.size() / 2, absolute.end());
    errors.idepth_relative_median = absolute[absolute.size() / 2];
  }
  return errors;
}

WindowedBAErrors EvaluateWindowedBAInput(const WindowedBASimulation& simulation,
                                         const std::vector<WindowedBAResultPoint>& points) {
  std::vector<SE3> poses;
  for (const WindowedBAKeyframe& keyframe : simulation.window.keyframes) {
    poses.push_back(keyframe.cam_from_world);
  }
  std::vector<WindowedBAResultPoint> inputs = points;
  for (WindowedBAResultPoint& point : inputs) {
    point.idepth = simulation.window.keyframes[point.keyframe_id].points[point.point_index].idepth;
  }
  return EvaluateWindowedBA(simulation, poses, inputs);
}

}  // namespace pldvo
