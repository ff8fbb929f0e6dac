// Options and presets, the camera path and its search, lighting over time, and the TUM writer.
#include "experiments/synthetic/synthetic_sequence.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/camera_model.h"
#include "core/camera_yaml.h"
#include "core/config_io.h"
#include "experiments/synthetic/frustum_culler.h"
#include "experiments/synthetic/synthetic_internal.h"

namespace pldvo::synthetic {
namespace {

using internal::Rng;

// Position and angle sums of sinusoids, and their derivatives.
double SumOfSines(const double amp[], const double freq[], const double phase[], double t) {
  double sum = 0.0;
  for (int k = 0; k < CameraPath::kTerms; ++k) sum += amp[k] * std::sin(freq[k] * t + phase[k]);
  return sum;
}

// Mean |dp/dt| and mean rotation rate over [0, duration] (duration > 0), by finite differences.
void MeanRates(const CameraPath& path, double duration, double* speed, double* angular_rate) {
  const int samples = 400;
  const double dt = duration / samples;
  double distance = 0.0, angle = 0.0;
  SE3 previous = path.WorldFromCam(0.0);
  for (int i = 1; i <= samples; ++i) {
    const SE3 current = path.WorldFromCam(i * dt);
    distance += (current.translation() - previous.translation()).norm();
    angle += LogSO3(previous.rotation_matrix().transpose() * current.rotation_matrix()).norm();
    previous = current;
  }
  *speed = distance / duration;
  *angular_rate = angle / duration;
}

// Multiplies the position (or angle) frequencies by a factor.
void ScaleFrequencies(double freq[3][CameraPath::kTerms], double factor) {
  for (int a = 0; a < 3; ++a) {
    for (int k = 0; k < CameraPath::kTerms; ++k) freq[a][k] *= factor;
  }
}

// Random amplitudes splitting `total` over the terms, frequencies around 1 rad per unit time.
void DrawTerms(Rng* rng, double total, double amp[], double freq[], double phase[]) {
  double weight[CameraPath::kTerms], sum = 0.0;
  for (int k = 0; k < CameraPath::kTerms; ++k) sum += weight[k] = rng->Uniform(0.2, 1.0);
  for (int k = 0; k < CameraPath::kTerms; ++k) {
    amp[k] = total * weight[k] / sum;
    freq[k] = rng->Uniform(0.4, 1.6) * (1.0 + 0.6 * k);
    phase[k] = rng->Uniform(0.0, 2.0 * M_PI);
  }
}

CameraPath DrawPath(const Scene& scene, const SynthOptions& options, double amplitude_scale,
                    Rng* rng) {
  const Eigen::Vector3d& room = scene.room_size();
  CameraPath path;
  // Several draws feeding one call are made first, last argument first (core/random_draws.h).
  const double center_z = rng->Uniform(1.4, 1.65);
  const double center_dy = rng->Uniform(-0.3, 0.3);
  const double center_dx = rng->Uniform(-0.3, 0.3);
  path.center = Eigen::Vector3d(0.5 * room.x() + center_dx, 0.5 * room.y() + center_dy, center_z);
  path.pivot_distance = options.pivot_distance;
  // Furniture reaches 0.65 m from a wall; the path keeps about 1.2 m from the walls.
  const double budget[3] = {std::max(0.1, 0.5 * room.x() - 1.2) * amplitude_scale,
                            std::max(0.1, 0.5 * room.y() - 1.2) * amplitude_scale, 0.15};
  for (int a = 0; a < 3; ++a) {
    DrawTerms(rng, budget[a], path.amp[a], path.freq[a], path.phase[a]);
  }
  const double base_pitch = rng->Uniform(-0.4, -0.15);
  const double base_yaw = rng->Uniform(0.0, 2.0 * M_PI);
  path.angle_offset = Eigen::Vector3d(base_yaw, base_pitch, 0.0);
  const double angle_budget[3] = {rng->Uniform(0.6, 1.3), options.pitch_amplitude,
                                  options.roll_amplitude};  // radians
  for (int a = 0; a < 3; ++a) {
    DrawTerms(rng, angle_budget[a], path.angle_amp[a], path.angle_freq[a], path.angle_phase[a]);
  }
  if (options.jitter_deg > 0.0) {
    // Physiological hand tremor sits at 4-12 Hz; one sinusoid per angle.
    for (int a = 0; a < 3; ++a) {
      const double phase = rng->Uniform(0.0, 2.0 * M_PI);
      const double hz = rng->Uniform(4.0, 10.0);
      path.jitter_amp[a] = options.jitter_deg * M_PI / 180.0;
      path.jitter_freq[a] = 2.0 * M_PI * hz;
      path.jitter_phase[a] = phase;
    }
  }
  // Time scaling: mean speed and rotation rate over the sequence equal the options'.
  const double duration = std::max(options.frames - 1, 1) / options.fps;
  for (int iteration = 0; iteration < 6; ++iteration) {
    double speed, angular_rate;
    MeanRates(path, duration, &speed, &angular_rate);
    ScaleFrequencies(path.freq, std::clamp(options.speed / std::max(speed, 1e-9), 0.2, 5.0));
    ScaleFrequencies(
        path.angle_freq,
        std::clamp(options.angular_speed * M_PI / 180.0 / std::max(angular_rate, 1e-9), 0.2, 5.0));
  }
  return path;
}

// Counts scene edges with at least `min_visible_px` pixels of unoccluded projection, up to
// `enough`. `in_view`: the primitives that rays through the image can hit.
int CountVisibleEdges(const Scene& scene, const PinholeCamera& camera, const SE3& world_from_cam,
                      const std::vector<int>& in_view, int enough) {
  const SE3 cam_from_world = world_from_cam.Inverse();
  constexpr int kSamples = 8;
  constexpr double kMinVisiblePx = 30.0;
  int visible_edges = 0;
  for (const Segment3d& edge : scene.edges()) {
    int visible_samples = 0;
    Eigen::Vector2d first_pixel, last_pixel;
    for (int i = 0; i < kSamples; ++i) {
      const double s = (i + 0.5) / kSamples;
      const Eigen::Vector3d point = (1 - s) * edge.start_in_world + s * edge.end_in_world;
      const Eigen::Vector3d point_in_cam = cam_from_world * point;
      if (point_in_cam.z() < 0.1) continue;
      const Eigen::Vector2d pixel = camera.Project(point_in_cam);
      if (!camera.IsInside(pixel, 2.0)) continue;
      Scene::Hit hit;
      const Eigen::Vector3d direction = point - world_from_cam.translation();
      if (!scene.IntersectSubset(world_from_cam.translation(), direction, in_view.data(),
                                 static_cast<int>(in_view.size()), &hit)) {
        continue;
      }
      if (hit.t < 1.0 - 0.01 / direction.norm()) continue;  // occluded (1 cm tolerance)
      if (visible_samples == 0) first_pixel = pixel;
      last_pixel = pixel;
      ++visible_samples;
    }
    if (visible_samples >= 2 && (last_pixel - first_pixel).norm() >= kMinVisiblePx) {
      if (++visible_edges >= enough) return visible_edges;
    }
  }
  return visible_edges;
}

// What a grid of rays covering the image (its corners included) hits: the minimum z-depth, and
// how many rays end on an occluder box. `in_view`: the primitives that rays through the image
// can hit.
struct GridProbe {
  double min_depth = std::numeric_limits<double>::infinity();
  int occluder_rays = 0;
};
GridProbe ProbeGrid(const Scene& scene, const PinholeCamera& camera, const SE3& world_from_cam,
                    const std::vector<int>& in_view) {
  constexpr int kCols = 24, kRows = 18;
  const Eigen::Matrix3d rotation = world_from_cam.rotation_matrix();
  GridProbe probe;
  for (int r = 0; r <= kRows; ++r) {
    for (int c = 0; c <= kCols; ++c) {
      const Eigen::Vector2d pixel(-0.5 + c * camera.width / static_cast<double>(kCols),
                                  -0.5 + r * camera.height / static_cast<double>(kRows));
      Scene::Hit hit;
      if (scene.IntersectSubset(world_from_cam.translation(), rotation * camera.Unproject(pixel),
                                in_view.data(), static_cast<int>(in_view.size()), &hit)) {
        probe.min_depth = std::min(probe.min_depth, hit.t);  // t is the z-depth for a z = 1 ray
        probe.occluder_rays += scene.primitives()[hit.primitive].name == kOccluderName;
      }
    }
  }
  return probe;
}

// "" when every frame keeps clearance, min depth and sees structure; else the first failure.
std::string CheckPath(const SyntheticSequence& sequence) {
  const SynthOptions& options = sequence.options;
  constexpr int kMinVisibleEdges = 4;
  // A scene with occluder boxes shows them (>= 1% of the probe's 475 rays) in at least half of
  // the frames: else its failure mode would not be in the sequence.
  constexpr int kMinOccluderRays = 5;
  int frames_with_occluders = 0;
  const PinholeCamera& camera = sequence.camera;
  const FrustumCuller culler(sequence.scene, camera);
  std::vector<int> in_view;
  for (const StampedPose& pose : sequence.ground_truth) {
    const SE3& world_from_cam = pose.world_from_cam;
    std::ostringstream failure;
    failure << "t=" << pose.timestamp << ": ";
    const double distance = sequence.scene.DistanceToSurfaces(world_from_cam.translation());
    if (distance < options.clearance) {
      failure << "clearance " << distance;
      return failure.str();
    }
    // Both checks cast rays through the image only (exact culling).
    culler.Candidates(-0.5, -0.5, camera.width - 0.5, camera.height - 0.5,
                      world_from_cam.rotation_matrix(), world_from_cam.translation(), culler.all(),
                      &in_view);
    const GridProbe probe = ProbeGrid(sequence.scene, camera, world_from_cam, in_view);
    if (probe.min_depth < options.min_depth) {
      failure << "min depth " << probe.min_depth;
      return failure.str();
    }
    frames_with_occluders += probe.occluder_rays >= kMinOccluderRays;
    if (CountVisibleEdges(sequence.scene, camera, world_from_cam, in_view, kMinVisibleEdges) <
        kMinVisibleEdges) {
      failure << "fewer than " << kMinVisibleEdges << " visible edges";
      return failure.str();
    }
  }
  const int frames = static_cast<int>(sequence.ground_truth.size());
  if (options.occluder_boxes > 0 && 2 * frames_with_occluders < frames) {
    return "occluder boxes in view in " + std::to_string(frames_with_occluders) + " of " +
           std::to_string(frames) + " frames";
  }
  return "";
}

std::string FrameName(int index) {
  std::ostringstream name;
  name << std::setw(6) << std::setfill('0') << index << ".png";
  return name.str();
}

void WriteOrThrow(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("WriteSequence: cannot write " + path);
}

bool IsPreset(const std::string& name) {
  for (const char* preset : {"textured", "lowtex", "lighting", "fast", "autoexposure",
                             "checkerboard", "boxes", "handheld"}) {
    if (name == preset) return true;
  }
  return false;
}

}  // namespace

std::string SynthOptions::Check() const {
  if (!IsPreset(preset)) {
    return "preset: '" + preset +
           "' is not one of textured | lowtex | lighting | fast | autoexposure | checkerboard | "
           "boxes | handheld";
  }
  if (frames < 1) return "frames: must be >= 1";
  if (seed < 0) return "seed: must be >= 0";
  if (width < 8 || height < 8) return "width, height: must be >= 8";
  if (!(fx > 0.0) || !(fy > 0.0)) return "fx, fy: must be > 0";
  if (!(fps > 0.0)) return "fps: must be > 0";
  if (!(noise_sigma >= 0.0)) return "noise_sigma: must be >= 0";
  if (supersampling < 1 || supersampling > 16) return "supersampling: must be in [1, 16]";
  if (!(texture_filter_sigma_px >= 0.0 && texture_filter_sigma_px <= 4.0)) {
    return "texture_filter_sigma_px: must be in [0, 4]";
  }
  if (motion_blur_samples < 1 || motion_blur_samples > 64) {
    return "motion_blur_samples: must be in [1, 64]";
  }
  if (!(exposure >= 0.0 && exposure <= 1.0)) return "exposure: must be in [0, 1]";
  if (!(vignetting_strength >= 0.0 && vignetting_strength <= 1.0)) {
    return "vignetting_strength: must be in [0, 1]";
  }
  if (!(lighting_period > 0.0)) return "lighting_period: must be > 0";
  if (!(contrast >= 0.0 && contrast <= 10.0)) return "contrast: must be in [0, 10]";
  if (!(brightness >= -1.0 && brightness <= 1.0)) return "brightness: must be in [-1, 1]";
  if (!(auto_exposure_amplitude < 1.0)) return "auto_exposure_amplitude: must be < 1";
  if (!(auto_exposure_period > 0.0)) return "auto_exposure_period: must be > 0";
  if (occluder_boxes > 40) return "occluder_boxes: must be <= 40";
  if (!(pitch_amplitude < 1.0) || !(roll_amplitude < 1.0)) {
    return "pitch_amplitude, roll_amplitude: must be < 1 rad";
  }
  if (!(jitter_deg < 5.0)) return "jitter_deg: must be < 5";
  if (!(pivot_distance >= 0.0 && pivot_distance <= 2.0)) return "pivot_distance: must be in [0, 2]";
  if (!(ambient >= 0.0) || !(light_intensity >= 0.0)) {
    return "ambient, light_intensity: must be >= 0";
  }
  if (!(albedo_variation >= 0.0 && albedo_variation < 1.0)) {
    return "albedo_variation: must be in [0, 1)";
  }
  if (!(min_depth >= 0.0) || !(clearance >= 0.0)) return "min_depth, clearance: must be >= 0";
  if (threads < 0) return "threads: must be >= 0";
  return "";
}

SynthOptions ResolvePreset(const SynthOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw std::invalid_argument("SynthOptions: " + problem);
  SynthOptions resolved = options;
  const bool fast = options.preset == "fast";
  const bool textured = options.preset == "textured";
  const bool lighting = options.preset == "lighting";
  const bool handheld = options.preset == "handheld";
  // Handheld: TUM fr1/rpy-like rotation about all three axes with little translation.
  if (resolved.speed < 0.0) resolved.speed = fast ? 0.75 : handheld ? 0.15 : 0.25;
  if (resolved.angular_speed < 0.0) resolved.angular_speed = fast ? 45.0 : handheld ? 40.0 : 15.0;
  if (resolved.pitch_amplitude < 0.0) resolved.pitch_amplitude = handheld ? 0.35 : 0.2;
  if (resolved.roll_amplitude < 0.0) resolved.roll_amplitude = handheld ? 0.3 : 0.07;
  if (resolved.jitter_deg < 0.0) resolved.jitter_deg = handheld ? 0.15 : 0.0;
  if (resolved.auto_exposure_amplitude < 0.0) {
    resolved.auto_exposure_amplitude = options.preset == "autoexposure" ? 0.3 : 0.0;
  }
  if (resolved.checker_size < 0.0) {
    resolved.checker_size = options.preset == "checkerboard" ? 0.08 : 0.0;
  }
  if (resolved.occluder_boxes < 0) resolved.occluder_boxes = options.preset == "boxes" ? 16 : 0;
  if (resolved.texture_contrast < 0.0) resolved.texture_contrast = textured ? 0.3 : 0.0;
  if (resolved.gain_amplitude < 0.0) resolved.gain_amplitude = lighting ? 0.25 : 0.0;
  if (resolved.bias_amplitude < 0.0) resolved.bias_amplitude = lighting ? 15.0 : 0.0;
  if (resolved.light_motion < 0.0) resolved.light_motion = lighting ? 1.0 : 0.0;
  if (resolved.cx < 0.0) resolved.cx = 0.5 * (resolved.width - 1);
  if (resolved.cy < 0.0) resolved.cy = 0.5 * (resolved.height - 1);
  return resolved;
}

Eigen::Vector3d CameraPath::PositionInWorld(double time) const {
  Eigen::Vector3d position = center;
  for (int a = 0; a < 3; ++a) position[a] += SumOfSines(amp[a], freq[a], phase[a], time);
  return position;
}

Eigen::Vector3d CameraPath::Angles(double time) const {
  Eigen::Vector3d angles = angle_offset;
  for (int a = 0; a < 3; ++a) {
    angles[a] += SumOfSines(angle_amp[a], angle_freq[a], angle_phase[a], time);
    if (jitter_amp[a] != 0.0)
      angles[a] += jitter_amp[a] * std::sin(jitter_freq[a] * time + jitter_phase[a]);
  }
  return angles;
}

SE3 CameraPath::WorldFromCam(double time) const {
  const Eigen::Vector3d angles = Angles(time);
  const double yaw = angles[0], pitch = angles[1], roll = angles[2];
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                std::sin(pitch));
  // x = forward x up is horizontal and to the right; y = z x x points down.
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation << right, down, forward;
  world_from_cam_rotation = world_from_cam_rotation *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return SE3(world_from_cam_rotation,
             PositionInWorld(time) + pivot_distance * world_from_cam_rotation.col(2));
}

Lighting LightingAt(const SyntheticSequence& sequence, double time) {
  const SynthOptions& options = sequence.options;
  // Phases derived from the seed so that sequences differ; fixed per sequence.
  Rng rng(static_cast<uint64_t>(options.seed) * 0x9E3779B97F4A7C15ull + 4242);
  const double gain_phase = rng.Uniform(0.0, 2.0 * M_PI);
  const double bias_phase = rng.Uniform(0.0, 2.0 * M_PI);
  const double light_phase = rng.Uniform(0.0, 2.0 * M_PI);
  const double w = 2.0 * M_PI / options.lighting_period;
  Lighting lighting;
  lighting.gain = 1.0 + options.gain_amplitude * std::sin(w * time + gain_phase);
  lighting.bias = options.bias_amplitude * std::sin(0.7 * w * time + bias_phase);
  lighting.light_in_world =
      sequence.scene.light_in_world() +
      options.light_motion *
          Eigen::Vector3d(std::cos(w * time + light_phase), std::sin(w * time + light_phase), 0.0);
  // The camera's side: auto-exposure a(t) scales the exposure (so the scene's gain and bias),
  // then I -> contrast (I - 127.5) + 127.5 + 255 brightness. Folded into one affine map, so the
  // noise is added after it (in gray levels) and the 8-bit rounding clips the result.
  if (options.auto_exposure_amplitude > 0.0) {
    // A smooth random walk of the gain: random knots every auto_exposure_period seconds,
    // smoothstep between them (value noise along time).
    const uint32_t ae_seed = static_cast<uint32_t>(internal::Mix64(options.seed + 0xAE0ull));
    const double noise = internal::ValueNoise(time / options.auto_exposure_period, 0.0, ae_seed);
    const double exposure_gain = 1.0 + options.auto_exposure_amplitude * (2.0 * noise - 1.0);
    lighting.gain *= exposure_gain;
    lighting.bias *= exposure_gain;
  }
  if (options.contrast != 1.0 || options.brightness != 0.0) {
    constexpr double kMidGray = 127.5;
    lighting.gain *= options.contrast;
    lighting.bias =
        options.contrast * (lighting.bias - kMidGray) + kMidGray + 255.0 * options.brightness;
  }
  return lighting;
}

SyntheticSequence MakeSequence(const SynthOptions& options) {
  SyntheticSequence sequence;
  sequence.options = ResolvePreset(options);
  const SynthOptions& resolved = sequence.options;
  sequence.camera.width = resolved.width;
  sequence.camera.height = resolved.height;
  sequence.camera.fx = resolved.fx;
  sequence.camera.fy = resolved.fy;
  sequence.camera.cx = resolved.cx;
  sequence.camera.cy = resolved.cy;
  SceneStyle style;
  style.checker_size = resolved.checker_size;
  style.occluder_boxes = resolved.occluder_boxes;
  sequence.scene = Scene::Generate(static_cast<uint64_t>(resolved.seed), style);

  Rng rng(static_cast<uint64_t>(resolved.seed) * 0xD1342543DE82EF95ull + 101);
  constexpr int kAttempts = 60;
  std::string failure;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    // Shrink the motion's extent on repeated failures.
    const double amplitude_scale = 1.0 - 0.6 * attempt / kAttempts;
    sequence.path = DrawPath(sequence.scene, resolved, amplitude_scale, &rng);
    sequence.ground_truth.resize(resolved.frames);
    for (int i = 0; i < resolved.frames; ++i) {
      sequence.ground_truth[i].timestamp = i / resolved.fps;
      sequence.ground_truth[i].world_from_cam = sequence.path.WorldFromCam(i / resolved.fps);
    }
    failure = CheckPath(sequence);
    if (failure.empty()) return sequence;
  }
  throw std::runtime_error(
      "MakeSequence: no trajectory met clearance, min_depth and visible "
      "structure after " +
      std::to_string(kAttempts) + " attempts (last: " + failure + ")");
}

double WriteSequence(const SyntheticSequence& sequence, const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(fs::path(dir) / "rgb");
  fs::create_directories(fs::path(dir) / "depth");
  const std::string prefix = dir + "/";
  std::ofstream rgb_list(prefix + "rgb.txt"), depth_list(prefix + "depth.txt"),
      lighting_list(prefix + "lighting.txt");
  if (!rgb_list || !depth_list || !lighting_list) {
    throw std::runtime_error("WriteSequence: cannot write in " + dir);
  }
  rgb_list << "# gray images (8-bit) rendered by pldvo synth\n# timestamp filename\n";
  depth_list << "# depth images (16-bit, metres x 5000, 0 = none) rendered by pldvo synth\n"
                "# timestamp filename\n";
  lighting_list << "# global photometric state of each frame: I = gain * radiance + bias + noise\n"
                   "# timestamp gain bias\n"
                << std::setprecision(9);
  double render_seconds = 0.0;
  for (int i = 0; i < static_cast<int>(sequence.ground_truth.size()); ++i) {
    const auto start = std::chrono::steady_clock::now();
    const RenderedFrame frame = RenderFrame(sequence, i);
    render_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cv::Mat depth_mm;
    frame.depth.convertTo(depth_mm, CV_16U, 5000.0);  // saturates beyond 13.1 m
    const std::string name = FrameName(i);
    WriteOrThrow(prefix + "rgb/" + name, frame.image);
    WriteOrThrow(prefix + "depth/" + name, depth_mm);
    std::ostringstream stamp;
    stamp << std::fixed << std::setprecision(6) << sequence.ground_truth[i].timestamp;
    rgb_list << stamp.str() << " rgb/" << name << "\n";
    depth_list << stamp.str() << " depth/" << name << "\n";
    const Lighting lighting = LightingAt(sequence, sequence.ground_truth[i].timestamp);
    lighting_list << stamp.str() << " " << lighting.gain << " " << lighting.bias << "\n";
  }
  WriteTrajectoryTum(sequence.ground_truth, prefix + "groundtruth.txt");
  WriteCameraYaml(*MakeCameraModel("pinhole", sequence.camera, {}), prefix + "camera.yaml");
  std::ofstream lines(prefix + "lines.txt");
  lines << "# 3D edge segments of the scene in the world frame: x1 y1 z1 x2 y2 z2 (metres)\n";
  lines << std::setprecision(9);
  for (const Segment3d& edge : sequence.scene.edges()) {
    lines << edge.start_in_world.x() << " " << edge.start_in_world.y() << " "
          << edge.start_in_world.z() << " " << edge.end_in_world.x() << " " << edge.end_in_world.y()
          << " " << edge.end_in_world.z() << "\n";
  }
  WriteConfigYaml(sequence.options, prefix + "synth_config.yaml");
  if (!lines) throw std::runtime_error("WriteSequence: cannot write in " + dir);
  return render_seconds > 0.0 ? sequence.ground_truth.size() / render_seconds : 0.0;
}

}  // namespace pldvo::synthetic
