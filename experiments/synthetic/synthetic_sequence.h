// Synthetic indoor sequences with exact ground truth: a room of planes and boxes (walls, floor,
// ceiling, cabinets, a table, a door, picture frames, shelves) drawn from a seed, rendered by
// per-pixel analytic ray casting with Lambertian shading (ambient + one point light),
// adaptive supersampling at surface boundaries, Gaussian sensor noise, optional motion blur and
// vignetting. The camera follows a smooth handheld-like trajectory at 30 fps that stays inside
// the free space of the room and always looks at scene content.
//
// Conventions: world frame z up, floor at z = 0, the room spans [0, room_size.x] x
// [0, room_size.y] x [0, room_size.z]; camera x right, y down, z forward; poses are
// world_from_cam; depth is the z-depth in metres of the surface seen at the pixel centre.
// See docs/synthetic.md.
#ifndef PLDVO_EXPERIMENTS_SYNTHETIC_SYNTHETIC_SEQUENCE_H_
#define PLDVO_EXPERIMENTS_SYNTHETIC_SYNTHETIC_SEQUENCE_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/options.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "core/trajectory_io.h"

namespace pldvo::synthetic {

// Every parameter of a sequence. Fields documented "< 0: preset" take their value from the
// preset unless set; ResolvePreset() fills them in (MakeSequence calls it).
struct SynthOptions {
  // textured | lowtex | lighting | fast, and the failure families of the line term (all on
  // lowtex's albedo): autoexposure | checkerboard | boxes | handheld (docs/synthetic.md).
  std::string preset = "lowtex";
  int frames = 300;
  int seed = 1;  // scene layout, trajectory and noise; any value >= 0
  int width = 640;
  int height = 480;
  double fx = 525.0;
  double fy = 525.0;
  double cx = -1.0;  // < 0: (width - 1) / 2
  double cy = -1.0;  // < 0: (height - 1) / 2
  double fps = 30.0;
  double noise_sigma = 1.0;              // gray levels, Gaussian, i.i.d. per pixel
  int supersampling = 4;                 // n x n samples at pixels on a surface boundary; 1 = off
  double texture_filter_sigma_px = 0.0;  // Gaussian pixel response on textures; 0 = point samples
  bool motion_blur = false;
  int motion_blur_samples = 5;  // sub-frame poses averaged when motion_blur
  double exposure = 0.5;        // exposure time as a fraction of the frame interval
  bool vignetting = false;
  double vignetting_strength = 0.3;  // relative darkening at the image corners
  double speed = -1.0;               // mean camera speed in m/s; < 0: preset (0.25, fast 0.75)
  double angular_speed = -1.0;       // mean rotation rate in deg/s; < 0: preset (15, fast 45)
  double texture_contrast = -1.0;    // albedo pattern amplitude; < 0: preset (textured 0.3, else 0)
  double albedo_variation = 0.03;    // smooth 1 m-scale albedo variation on every surface
  double gain_amplitude = -1.0;      // relative global gain swing; < 0: preset (lighting 0.25)
  double bias_amplitude = -1.0;      // global bias swing in gray levels; < 0: preset (lighting 15)
  double light_motion = -1.0;        // radius in m of the moving light's circle; < 0: preset
  double lighting_period = 8.0;      // seconds per cycle of gain, bias and light motion
  // Camera-side photometry, applied to the image before the noise (docs/synthetic.md):
  // I = contrast (a(t) I_scene - 127.5) + 127.5 + 255 brightness, a(t) the auto-exposure gain.
  double contrast = 1.0;                  // scale of the deviation from mid-gray
  double brightness = 0.0;                // offset as a fraction of 255
  double auto_exposure_amplitude = -1.0;  // a(t) in 1 +- this; < 0: preset (autoexposure 0.3)
  double auto_exposure_period = 2.0;      // seconds between the gain's random knots
  double checker_size = -1.0;     // m; walls and floor black/white squares; < 0: preset (0.08)
  int occluder_boxes = -1;        // plain boxes 0.7-1.35 m before the walls; < 0: preset (boxes 16)
  double pitch_amplitude = -1.0;  // rad, pitch swing of the path; < 0: preset (0.2, handheld 0.35)
  double roll_amplitude = -1.0;   // rad, roll swing of the path; < 0: preset (0.07, handheld 0.3)
  double jitter_deg = -1.0;       // hand tremor per axis, 4-10 Hz; < 0: preset (handheld 0.15)
  double pivot_distance = 0.0;    // m; the camera turns about a point this far behind its centre
  double ambient = 0.35;          // ambient term of the shading (albedo 1 -> 255 * ambient)
  double light_intensity = 0.75;  // point-light term at normal incidence, 2.5 m away
  double min_depth = 0.5;         // metres: every pixel of every frame sees at least this far
  double clearance = 0.35;        // metres from the camera centre to any surface
  int threads = 0;                // render threads; 0 = hardware concurrency

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("preset", &preset,
            "Scene appearance and motion: textured | lowtex | lighting | fast | autoexposure | "
            "checkerboard | boxes | handheld.");
    v.Field("frames", &frames, "Number of frames (30 fps).");
    v.Field("seed", &seed, "Seed of the scene layout, trajectory and noise (>= 0).");
    v.Field("width", &width, "Image width in pixels.");
    v.Field("height", &height, "Image height in pixels.");
    v.Field("fx", &fx, "Focal length in x (pixels).");
    v.Field("fy", &fy, "Focal length in y (pixels).");
    v.Field("cx", &cx, "Principal point x (pixels); < 0 centres it at (width - 1) / 2.");
    v.Field("cy", &cy, "Principal point y (pixels); < 0 centres it at (height - 1) / 2.");
    v.Field("fps", &fps, "Frame rate of the timestamps and of the motion.");
    v.Field("noise_sigma", &noise_sigma, "Gaussian sensor noise, gray levels (0 = off).");
    v.Field("supersampling", &supersampling,
            "n x n samples per pixel on surface boundaries (anti-aliasing); 1 = off.");
    v.Field("texture_filter_sigma_px", &texture_filter_sigma_px,
            "Std. dev. in pixels of the Gaussian pixel response that band-limits the textures "
            "(0 = point samples, which alias fine patterns at grazing angles).");
    v.Field("motion_blur", &motion_blur, "Average sub-frame renderings over the exposure.");
    v.Field("motion_blur_samples", &motion_blur_samples, "Sub-frames per motion-blurred frame.");
    v.Field("exposure", &exposure, "Exposure as a fraction of the frame interval (motion blur).");
    v.Field("vignetting", &vignetting, "Darken the image towards the corners.");
    v.Field("vignetting_strength", &vignetting_strength,
            "Relative darkening at the corners: I *= 1 - s (r / r_corner)^2.");
    v.Field("speed", &speed, "Mean camera speed in m/s; < 0: preset (0.25, fast 0.75).");
    v.Field("angular_speed", &angular_speed,
            "Mean camera rotation rate in deg/s; < 0: preset (15, fast 45).");
    v.Field("texture_contrast", &texture_contrast,
            "Amplitude of the procedural albedo pattern; < 0: preset (textured 0.3, else 0).");
    v.Field("albedo_variation", &albedo_variation,
            "Amplitude of a smooth (1 m cells) albedo variation on every surface.");
    v.Field("gain_amplitude", &gain_amplitude,
            "Relative swing of the global gain; < 0: preset (lighting 0.25, else 0).");
    v.Field("bias_amplitude", &bias_amplitude,
            "Swing of the global bias in gray levels; < 0: preset (lighting 15, else 0).");
    v.Field("light_motion", &light_motion,
            "Radius in m of the point light's circular motion; < 0: preset (lighting 1, else 0).");
    v.Field("lighting_period", &lighting_period,
            "Seconds per cycle of the gain, bias and light motion.");
    v.Field("contrast", &contrast,
            "Image contrast around mid-gray: I = c (I - 127.5) + 127.5, before the noise.");
    v.Field("brightness", &brightness,
            "Image brightness offset as a fraction of 255 (0.2 = +51 gray levels), before the "
            "noise.");
    v.Field("auto_exposure_amplitude", &auto_exposure_amplitude,
            "Auto-exposure: a smooth random global gain in 1 +- this; < 0: preset "
            "(autoexposure 0.3, else 0).");
    v.Field("auto_exposure_period", &auto_exposure_period,
            "Seconds between the auto-exposure gain's random knots (smoothstep in between).");
    v.Field("checker_size", &checker_size,
            "Square size in m of a black/white checkerboard on the walls and floor; 0 = none; "
            "< 0: preset (checkerboard 0.08, else 0).");
    v.Field("occluder_boxes", &occluder_boxes,
            "Plain boxes standing 0.7-1.35 m in front of the walls (occlusion edges); < 0: preset "
            "(boxes 16, else 0).");
    v.Field("pitch_amplitude", &pitch_amplitude,
            "Pitch swing of the camera path in rad; < 0: preset (0.2, handheld 0.35).");
    v.Field("roll_amplitude", &roll_amplitude,
            "Roll swing of the camera path in rad; < 0: preset (0.07, handheld 0.3).");
    v.Field("jitter_deg", &jitter_deg,
            "Hand tremor: per-axis rotation jitter amplitude in degrees at 4-10 Hz; < 0: preset "
            "(handheld 0.15, else 0).");
    v.Field("pivot_distance", &pivot_distance,
            "Metres behind the optical centre of the point the camera turns about (a wrist, a "
            "car's rear axle: turning moves the centre); 0: turns about its centre. The mean "
            "speed cannot drop below what the turns alone give.");
    v.Field("ambient", &ambient, "Ambient shading term.");
    v.Field("light_intensity", &light_intensity,
            "Point-light shading term at normal incidence and 2.5 m distance.");
    v.Field("min_depth", &min_depth, "Minimum depth (m) of every pixel of every frame.");
    v.Field("clearance", &clearance, "Minimum distance (m) from the camera to any surface.");
    v.Field("threads", &threads, "Render threads; 0 = hardware concurrency.");
  }
  // "" when valid, otherwise what is wrong (names the field).
  std::string Check() const;
};

// The options with every "< 0: preset" field filled from the preset, and cx, cy centred.
// Throws std::invalid_argument on an unknown preset or invalid options.
SynthOptions ResolvePreset(const SynthOptions& options);

struct Segment3d {
  Eigen::Vector3d start_in_world;
  Eigen::Vector3d end_in_world;
};

struct RenderedFrame {
  cv::Mat image;  // CV_8U gray
  cv::Mat depth;  // CV_32F z-depth in metres, 0 where nothing is hit
};

// Primitive::name of the boxes that SceneStyle::occluder_boxes adds.
inline constexpr char kOccluderName[] = "occluder";

// One solid or the room's interior. A box is oriented: box_from_world maps the world into the
// box frame, where it spans [-half_size, half_size].
struct Primitive {
  enum class Kind { kRoom, kBox };
  // kChecker: squares of texture_scale in the face's coordinates, albedo or kCheckerDark x albedo
  // (independent of texture_contrast).
  enum class Pattern { kPlain, kNoise, kWood, kTiles, kChecker };
  Kind kind = Kind::kBox;
  Eigen::Matrix3d box_from_world_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d center_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_size = Eigen::Vector3d::Ones();
  double albedo[6] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5};  // faces -x, +x, -y, +y, -z, +z
  Pattern pattern[6] = {Pattern::kNoise, Pattern::kNoise, Pattern::kNoise,
                        Pattern::kNoise, Pattern::kNoise, Pattern::kNoise};
  double texture_scale = 0.1;  // metres per texture cell
  uint32_t texture_seed = 0;
  std::string name;  // "wall", "cabinet", "table_top", kOccluderName, ...
};

// What a pixel integrates at a ray's hit: the hit point's derivatives with respect to the image
// x and y (world frame, metres per pixel) and the standard deviation of the pixel's Gaussian
// response in pixels (0: the pixel samples the surface at one point).
struct PixelFootprint {
  Eigen::Vector3d point_per_x = Eigen::Vector3d::Zero();
  Eigen::Vector3d point_per_y = Eigen::Vector3d::Zero();
  double sigma_px = 0.0;

  // Ray differentials (Igehy 1999) on the hit's plane n . (p - p_hit) = 0, for the ray
  // origin + t direction whose direction changes by ray_per_x, ray_per_y per pixel: a direction
  // d + e meets the plane at p_hit + t (e - d (n . e) / (n . d)) to first order. A ray along the
  // plane gets a footprint so wide that the pattern takes its mean.
  static PixelFootprint OnPlane(const Eigen::Vector3d& normal, const Eigen::Vector3d& direction,
                                double t, const Eigen::Vector3d& ray_per_x,
                                const Eigen::Vector3d& ray_per_y, double sigma_px);
};

// Scene additions of the failure families; the defaults give the plain random room.
struct SceneStyle {
  double checker_size = 0.0;  // > 0: walls and floor are checkerboards of this square size (m)
  int occluder_boxes = 0;     // plain boxes standing 0.7-1.35 m in front of the walls
};

class Scene {
 public:
  // Dark squares of a checkerboard: this fraction of the face's albedo.
  static constexpr double kCheckerDark = 0.1;

  Scene() = default;
  // A random room layout drawn from the seed. The style's additions are drawn from their own
  // generator, so the room, its furniture and the light are those of the plain style.
  static Scene Generate(uint64_t seed, const SceneStyle& style = SceneStyle());

  const std::vector<Primitive>& primitives() const { return primitives_; }
  // The scene's 3D edge segments: the room's 12 edges and the edges of every box (box-on-wall
  // and box-on-floor contacts included, as they are visible boundaries). Edges shorter than
  // 5 cm are left out.
  const std::vector<Segment3d>& edges() const { return edges_; }
  // The room's interior extent from the origin (x, y, z), metres.
  const Eigen::Vector3d& room_size() const { return room_size_; }
  // Default light position (the lighting preset moves it around this point).
  const Eigen::Vector3d& light_in_world() const { return light_in_world_; }

  // Nearest surface along a ray (direction need not be normalised): the ray parameter t > 0
  // (point = origin + t * direction), the primitive index, face (0..5) and outward normal.
  // Returns false when nothing is hit.
  struct Hit {
    double t = 0.0;
    int primitive = -1;
    int face = -1;
    Eigen::Vector3d normal_in_world = Eigen::Vector3d::Zero();
  };
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Hit* hit) const;
  // The same over the primitives listed in `indices` (the renderer's per-tile candidates).
  bool IntersectSubset(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                       const int* indices, int count, Hit* hit) const;
  // Albedo at a hit point: the face's albedo times its procedural pattern
  // (1 + texture_contrast (2 w - 1), w in [0, 1]) and a smooth variation
  // (1 + albedo_variation (2 n - 1), n value noise of 1 m cells). With a footprint of
  // sigma_px > 0 the pattern is band-limited by the pixel's response (docs/synthetic.md,
  // "Texture filtering"): sinusoidal bands exactly, value noise and grout approximately.
  double Albedo(const Hit& hit, const Eigen::Vector3d& point_in_world, double texture_contrast,
                double albedo_variation, const PixelFootprint& footprint) const;
  // 1 on the dark squares of a checkerboard face, else 0 (the renderer anti-aliases the
  // squares' boundaries like surface boundaries).
  int CheckerParity(const Hit& hit, const Eigen::Vector3d& point_in_world) const;
  // Distance from a point to the nearest surface (room walls and boxes).
  double DistanceToSurfaces(const Eigen::Vector3d& point_in_world) const;

  // For building scenes by hand (tests): adds a primitive and its edges.
  void AddPrimitive(const Primitive& primitive);
  void SetRoom(const Eigen::Vector3d& room_size);
  void SetLight(const Eigen::Vector3d& light_in_world) { light_in_world_ = light_in_world; }

 private:
  std::vector<Primitive> primitives_;
  std::vector<Segment3d> edges_;
  Eigen::Vector3d room_size_ = Eigen::Vector3d(5.0, 5.0, 2.7);
  Eigen::Vector3d light_in_world_ = Eigen::Vector3d(2.5, 2.5, 2.4);
};

// The continuous camera motion: position and viewing angles are sums of sinusoids of time
// (smooth, bounded, handheld-like). Positions: p_a(t) = center_a + sum_k amp sin(freq t + phase)
// for a = x, y, z; angles (yaw about world z, pitch, roll) alike, around angle_offset.
struct CameraPath {
  static constexpr int kTerms = 3;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d angle_offset = Eigen::Vector3d::Zero();  // yaw, pitch, roll in radians
  double amp[3][kTerms] = {}, freq[3][kTerms] = {}, phase[3][kTerms] = {};
  double angle_amp[3][kTerms] = {}, angle_freq[3][kTerms] = {}, angle_phase[3][kTerms] = {};
  // Hand tremor: one fast sinusoid per angle (rad, rad/s), not rescaled with the motion.
  double jitter_amp[3] = {}, jitter_freq[3] = {}, jitter_phase[3] = {};
  // The camera centre is this far ahead of PositionInWorld along its optical axis, m.
  double pivot_distance = 0.0;
  Eigen::Vector3d PositionInWorld(double time) const;
  // yaw, pitch, roll (tremor included).
  Eigen::Vector3d Angles(double time) const;
  // Camera looking along (cos p cos y, cos p sin y, sin p) with x horizontal (before the roll),
  // then rolled about its z axis.
  SE3 WorldFromCam(double time) const;
};

struct SyntheticSequence {
  SynthOptions options;  // resolved (ResolvePreset)
  PinholeCamera camera;
  Scene scene;
  Trajectory ground_truth;  // world_from_cam per frame; timestamps index / fps
  CameraPath path;          // ground_truth[i].world_from_cam == path.WorldFromCam(i / fps)
};

// Global photometric state at a time: I = gain * radiance + bias, and the light position. gain
// and bias include the lighting preset's swing, the auto-exposure gain, contrast and brightness.
struct Lighting {
  double gain = 1.0;
  double bias = 0.0;
  Eigen::Vector3d light_in_world = Eigen::Vector3d::Zero();
};
Lighting LightingAt(const SyntheticSequence& sequence, double time);

// Draws the scene and trajectory; throws std::invalid_argument on invalid options and
// std::runtime_error when no trajectory meeting clearance and min_depth is found.
SyntheticSequence MakeSequence(const SynthOptions& options);
// Frame `index` with every effect the options enable. Deterministic: the noise is seeded by
// (seed, index, pixel), independent of the thread count.
RenderedFrame RenderFrame(const SyntheticSequence& sequence, int index);
// A noise-free, blur-free, vignetting-free view from any pose with the lighting of time 0
// (for tests).
RenderedFrame RenderView(const SyntheticSequence& sequence, const SE3& world_from_cam);
// TUM layout: rgb/ (8-bit gray PNG), depth/ (16-bit PNG, metres x 5000), rgb.txt, depth.txt,
// groundtruth.txt (world_from_cam), camera.yaml (pinhole), lines.txt (x1 y1 z1 x2 y2 z2 in
// world per line), synth_config.yaml (the resolved options). Creates `dir`. Returns the
// rendering rate in frames per second (rendering only, without PNG encoding).
double WriteSequence(const SyntheticSequence& sequence, const std::string& dir);

}  // namespace pldvo::synthetic

#endif  // PLDVO_EXPERIMENTS_SYNTHETIC_SYNTHETIC_SEQUENCE_H_
