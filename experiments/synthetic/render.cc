// Per-pixel ray casting of the synthetic scene.
//
// Radiance of a surface point p with albedo a and normal n (Lambertian, one point light at l):
//   L = 255 a (ambient + light_intensity max(0, n . (l - p) / |l - p|) min(1.4, 2.5 / |l - p|))
// (a softened 1/d falloff, normalised to 1 at 2.5 m). The image is
//   I = gain(t) V(r) L + bias(t) + n,  n ~ N(0, noise_sigma^2),
// rounded and clamped to [0, 255], with V(r) = 1 - s (r / r_corner)^2 the vignetting. With
// texture_filter_sigma_px > 0 the albedo pattern is band-limited by a Gaussian pixel response,
// carried onto the surface by ray differentials (PixelFootprint).
// Pass 1 casts one ray through each pixel centre and records the surface (primitive, face) and
// z-depth; pass 2 re-renders pixels whose 8-neighbourhood holds another surface with n x n
// sub-pixel rays (anti-aliasing); a checkerboard's squares count as surfaces. Each 16x16 tile only
// tests the boxes that meet the tile's frustum, and each supersampled pixel only those of the tile
// that meet the pixel's frustum.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

#include "experiments/synthetic/frustum_culler.h"
#include "experiments/synthetic/synthetic_internal.h"
#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::synthetic {
namespace {

constexpr int kTile = 16;

struct ShadingParams {
  double ambient;
  double light_intensity;
  double texture_contrast;
  double albedo_variation;
  double texture_filter_sigma_px;
  Eigen::Vector3d light_in_world;
};

// Runs fn(item) for item in [0, count) on `threads` threads (dynamic assignment; the result
// does not depend on it because items write disjoint outputs).
template <typename Fn>
void ParallelFor(int count, int threads, Fn fn) {
  if (threads <= 1 || count <= 1) {
    for (int i = 0; i < count; ++i) fn(i);
    return;
  }
  std::atomic<int> next(0);
  auto worker = [&]() {
    for (int i = next++; i < count; i = next++) fn(i);
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
}

int ThreadCount(const SynthOptions& options) {
  if (options.threads > 0) return options.threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

class Renderer {
 public:
  Renderer(const Scene& scene, const PinholeCamera& camera, const ShadingParams& shading,
           int supersampling, int threads)
      : scene_(scene),
        camera_(camera),
        shading_(shading),
        supersampling_(supersampling),
        threads_(threads),
        tiles_x_((camera.width + kTile - 1) / kTile),
        tiles_y_((camera.height + kTile - 1) / kTile),
        culler_(scene, camera) {}

  // Radiance (before gain, bias, vignetting, noise) and z-depth of every pixel.
  void Render(const SE3& world_from_cam, float* radiance, float* depth) const {
    const int n = camera_.width * camera_.height;
    std::vector<int> surface(n);
    const Eigen::Matrix3d rotation = world_from_cam.rotation_matrix();
    const Eigen::Vector3d origin = world_from_cam.translation();
    // Change of the (z = 1) ray direction per pixel along x and y, in the world frame.
    const Eigen::Vector3d centre_ray = camera_.Unproject(Eigen::Vector2d::Zero());
    const Eigen::Vector3d ray_per_x =
        rotation * (camera_.Unproject(Eigen::Vector2d::UnitX()) - centre_ray);
    const Eigen::Vector3d ray_per_y =
        rotation * (camera_.Unproject(Eigen::Vector2d::UnitY()) - centre_ray);
    const auto shade = [&](const Scene::Hit& hit, const Eigen::Vector3d& direction) {
      return Shade(hit, origin, direction, ray_per_x, ray_per_y);
    };
    const int tile_count = tiles_x_ * tiles_y_;
    // Pass 1: pixel centres.
    ParallelFor(tile_count, threads_, [&](int tile) {
      std::vector<int> candidates;
      int x0, y0, x1, y1;
      TileRange(tile, &x0, &y0, &x1, &y1);
      culler_.Candidates(x0 - 0.5, y0 - 0.5, x1 - 0.5, y1 - 0.5, rotation, origin, culler_.all(),
                         &candidates);
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const int i = y * camera_.width + x;
          Scene::Hit hit;
          const Eigen::Vector3d direction = rotation * camera_.Unproject(Eigen::Vector2d(x, y));
          if (scene_.IntersectSubset(origin, direction, candidates.data(),
                                     static_cast<int>(candidates.size()), &hit)) {
            radiance[i] = static_cast<float>(shade(hit, direction));
            depth[i] = static_cast<float>(hit.t);  // the ray has z = 1 in the camera frame
            // A checkerboard's squares count as surfaces of their own, so that their
            // boundaries are anti-aliased like object edges.
            surface[i] = (hit.primitive * 6 + hit.face) * 2 +
                         scene_.CheckerParity(hit, origin + hit.t * direction);
          } else {
            radiance[i] = 0.0f;
            depth[i] = 0.0f;
            surface[i] = -1;
          }
        }
      }
    });
    if (supersampling_ <= 1) return;
    // Pass 2: supersample pixels on surface boundaries.
    const int w = camera_.width, h = camera_.height, ss = supersampling_;
    ParallelFor(tile_count, threads_, [&](int tile) {
      std::vector<int> candidates, pixel_candidates;
      bool have_candidates = false;
      int x0, y0, x1, y1;
      TileRange(tile, &x0, &y0, &x1, &y1);
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const int i = y * w + x;
          bool boundary = false;
          for (int dy = -1; dy <= 1 && !boundary; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
              const int nx = x + dx, ny = y + dy;
              if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
              if (surface[ny * w + nx] != surface[i]) {
                boundary = true;
                break;
              }
            }
          }
          if (!boundary) continue;
          if (!have_candidates) {
            culler_.Candidates(x0 - 0.5, y0 - 0.5, x1 - 0.5, y1 - 0.5, rotation, origin,
                               culler_.all(), &candidates);
            have_candidates = true;
          }
          // The sub-pixel rays only test what the pixel's own frustum can hold.
          culler_.Candidates(x - 0.5, y - 0.5, x + 0.5, y + 0.5, rotation, origin, candidates,
                             &pixel_candidates);
          double sum = 0.0;
          for (int sy = 0; sy < ss; ++sy) {
            for (int sx = 0; sx < ss; ++sx) {
              const Eigen::Vector2d pixel(x - 0.5 + (sx + 0.5) / ss, y - 0.5 + (sy + 0.5) / ss);
              const Eigen::Vector3d direction = rotation * camera_.Unproject(pixel);
              Scene::Hit hit;
              if (scene_.IntersectSubset(origin, direction, pixel_candidates.data(),
                                         static_cast<int>(pixel_candidates.size()), &hit)) {
                sum += shade(hit, direction);
              }
            }
          }
          radiance[i] = static_cast<float>(sum / (ss * ss));
        }
      }
    });
  }

  int threads() const { return threads_; }

 private:
  void TileRange(int tile, int* x0, int* y0, int* x1, int* y1) const {
    *x0 = (tile % tiles_x_) * kTile;
    *y0 = (tile / tiles_x_) * kTile;
    *x1 = std::min(*x0 + kTile, camera_.width);
    *y1 = std::min(*y0 + kTile, camera_.height);
  }

  // Radiance of the hit; ray_per_x, ray_per_y: the ray's change per pixel (for the footprint).
  double Shade(const Scene::Hit& hit, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction, const Eigen::Vector3d& ray_per_x,
               const Eigen::Vector3d& ray_per_y) const {
    const Eigen::Vector3d point = origin + hit.t * direction;
    const PixelFootprint footprint =
        PixelFootprint::OnPlane(hit.normal_in_world, direction, hit.t, ray_per_x, ray_per_y,
                                shading_.texture_filter_sigma_px);
    const double albedo =
        scene_.Albedo(hit, point, shading_.texture_contrast, shading_.albedo_variation, footprint);
    const Eigen::Vector3d to_light = shading_.light_in_world - point;
    const double distance = std::max(to_light.norm(), 1e-6);
    const double cosine = std::max(0.0, hit.normal_in_world.dot(to_light) / distance);
    const double falloff = std::min(1.4, 2.5 / distance);
    return 255.0 * albedo * (shading_.ambient + shading_.light_intensity * cosine * falloff);
  }

  const Scene& scene_;
  const PinholeCamera& camera_;
  ShadingParams shading_;
  int supersampling_;
  int threads_;
  int tiles_x_, tiles_y_;
  FrustumCuller culler_;
};

ShadingParams MakeShading(const SyntheticSequence& sequence, const Lighting& lighting) {
  const SynthOptions& o = sequence.options;
  return {o.ambient,          o.light_intensity,         o.texture_contrast,
          o.albedo_variation, o.texture_filter_sigma_px, lighting.light_in_world};
}

RenderedFrame AllocateFrame(const PinholeCamera& camera) {
  RenderedFrame frame;
  frame.image.create(camera.height, camera.width, CV_8U);
  frame.depth.create(camera.height, camera.width, CV_32F);
  return frame;
}

}  // namespace

RenderedFrame RenderFrame(const SyntheticSequence& sequence, int index) {
  const SynthOptions& options = sequence.options;
  if (index < 0 || index >= static_cast<int>(sequence.ground_truth.size())) {
    throw std::invalid_argument("RenderFrame: index " + std::to_string(index) + " outside [0, " +
                                std::to_string(sequence.ground_truth.size()) + ")");
  }
  const double time = sequence.ground_truth[index].timestamp;
  const Lighting lighting = LightingAt(sequence, time);
  const Renderer renderer(sequence.scene, sequence.camera, MakeShading(sequence, lighting),
                          options.supersampling, ThreadCount(options));
  const PinholeCamera& camera = sequence.camera;
  const int n = camera.width * camera.height;
  RenderedFrame frame = AllocateFrame(camera);
  float* depth = frame.depth.ptr<float>();
  std::vector<float> radiance(n);
  renderer.Render(sequence.ground_truth[index].world_from_cam, radiance.data(), depth);
  if (options.motion_blur && options.motion_blur_samples > 1) {
    // Average of sub-frames spread over the exposure, centred on the frame time; the depth is
    // the one of the frame's (central) pose.
    std::vector<double> sum(radiance.begin(), radiance.end());
    std::vector<float> sub_radiance(n), sub_depth(n);
    const int samples = options.motion_blur_samples;
    int rendered = 1;
    for (int j = 0; j < samples; ++j) {
      const double offset =
          (static_cast<double>(j) / (samples - 1) - 0.5) * options.exposure / options.fps;
      if (std::abs(offset) < 1e-12) continue;  // the central pose is already rendered
      renderer.Render(sequence.path.WorldFromCam(time + offset), sub_radiance.data(),
                      sub_depth.data());
      for (int i = 0; i < n; ++i) sum[i] += sub_radiance[i];
      ++rendered;
    }
    for (int i = 0; i < n; ++i) radiance[i] = static_cast<float>(sum[i] / rendered);
  }
  // Photometric model, vignetting and noise; the noise of a pixel depends only on
  // (seed, index, pixel).
  const uint64_t frame_key =
      internal::Mix64(internal::Mix64(static_cast<uint64_t>(options.seed) + 0x51ED2701ull) +
                      static_cast<uint64_t>(index));
  const double r_corner2 = camera.cx * camera.cx + camera.cy * camera.cy;
  ParallelFor(camera.height, renderer.threads(), [&](int y) {
    uint8_t* row = frame.image.ptr<uint8_t>(y);
    for (int x = 0; x < camera.width; ++x) {
      const int i = y * camera.width + x;
      double value = radiance[i];
      if (options.vignetting) {
        const double dx = x - camera.cx, dy = y - camera.cy;
        value *= 1.0 - options.vignetting_strength * (dx * dx + dy * dy) / r_corner2;
      }
      value = lighting.gain * value + lighting.bias;
      if (options.noise_sigma > 0.0) {
        value += options.noise_sigma *
                 internal::GaussianFromKey(frame_key ^ (static_cast<uint64_t>(i) << 1));
      }
      row[x] = static_cast<uint8_t>(std::clamp(std::lround(value), 0l, 255l));
    }
  });
  return frame;
}

RenderedFrame RenderView(const SyntheticSequence& sequence, const SE3& world_from_cam) {
  const SynthOptions& options = sequence.options;
  const Lighting lighting = LightingAt(sequence, 0.0);
  const Renderer renderer(sequence.scene, sequence.camera, MakeShading(sequence, lighting),
                          options.supersampling, ThreadCount(options));
  const PinholeCamera& camera = sequence.camera;
  RenderedFrame frame = AllocateFrame(camera);
  std::vector<float> radiance(camera.width * camera.height);
  renderer.Render(world_from_cam, radiance.data(), frame.depth.ptr<float>());
  for (int y = 0; y < camera.height; ++y) {
    uint8_t* row = frame.image.ptr<uint8_t>(y);
    for (int x = 0; x < camera.width; ++x) {
      const double value = lighting.gain * radiance[y * camera.width + x] + lighting.bias;
      row[x] = static_cast<uint8_t>(std::clamp(std::lround(value), 0l, 255l));
    }
  }
  return frame;
}

}  // namespace pldvo::synthetic
