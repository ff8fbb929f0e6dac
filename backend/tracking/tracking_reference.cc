#include "backend/tracking/tracking_reference.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "core/image_pyramid.h"
#include "core/random_draws.h"

namespace pldvo {
namespace {

std::string Where(int line) { return std::string(__FILE__) + ":" + std::to_string(line) + ": "; }

void CheckInputs(const cv::Mat& image, const cv::Mat& depth, const PinholeCamera& camera,
                 const GroundTruthReferenceOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(Where(__LINE__) + error);
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) throw std::invalid_argument(Where(__LINE__) + camera_error);
  if (image.empty() || image.channels() != 1 || depth.type() != CV_32F ||
      image.size() != depth.size() || image.cols != camera.width || image.rows != camera.height) {
    throw std::invalid_argument(Where(__LINE__) +
                                "need a single-channel image and a CV_32F depth of the camera's "
                                "size");
  }
}

// Clips the segment p + s (q - p), s in [0, 1], to the rectangle [0, w-1] x [0, h-1]
// (Liang-Barsky). Returns false when nothing is inside.
bool ClipToImage(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double width, double height,
                 Eigen::Vector2d* p_clipped, Eigen::Vector2d* q_clipped) {
  const Eigen::Vector2d d = q - p;
  double s0 = 0.0;
  double s1 = 1.0;
  const double lo[2] = {0.0, 0.0};
  const double hi[2] = {width - 1.0, height - 1.0};
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(d[axis]) < 1e-12) {
      if (p[axis] < lo[axis] || p[axis] > hi[axis]) return false;
      continue;
    }
    double a = (lo[axis] - p[axis]) / d[axis];
    double b = (hi[axis] - p[axis]) / d[axis];
    if (a > b) std::swap(a, b);
    s0 = std::max(s0, a);
    s1 = std::min(s1, b);
    if (s0 > s1) return false;
  }
  *p_clipped = p + s0 * d;
  *q_clipped = p + s1 * d;
  return true;
}

// Clips a 3D segment to z >= min_z. Returns false when it lies entirely in front of that plane.
bool ClipToDepth(Eigen::Vector3d* a, Eigen::Vector3d* b, double min_z) {
  if (a->z() < min_z && b->z() < min_z) return false;
  if (a->z() < min_z) *a = *b + (min_z - b->z()) / (a->z() - b->z()) * (*a - *b);
  if (b->z() < min_z) *b = *a + (min_z - a->z()) / (b->z() - a->z()) * (*b - *a);
  return true;
}

bool VisibleInDepth(const cv::Mat& depth, const Eigen::Vector2d& pixel, double z) {
  const int u = static_cast<int>(std::lround(pixel.x()));
  const int v = static_cast<int>(std::lround(pixel.y()));
  for (int dv = -1; dv <= 1; ++dv) {
    for (int du = -1; du <= 1; ++du) {
      const int x = u + du;
      const int y = v + dv;
      if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) continue;
      const float d = depth.at<float>(y, x);
      if (d > 0.f && std::abs(d - z) < 0.02 * z) return true;
    }
  }
  return false;
}

constexpr double kMinDepth = 0.05;          // m, clipping plane of the GT segments
constexpr double kMinMatchedLength = 10.0;  // px at level 0 inside the current image

}  // namespace

const MatchedLine* MatchedLineOf(const TrackingReferenceLevel& ref, const ReferencePoint& point,
                                 int level) {
  if (point.edge_id < 0) return nullptr;
  if (point.edge_id >= static_cast<int>(ref.lines_in_cur.size())) {
    throw std::invalid_argument(Where(__LINE__) + "edge id " + std::to_string(point.edge_id) +
                                " has no line entry at level " + std::to_string(level));
  }
  const MatchedLine& line = ref.lines_in_cur[point.edge_id];
  return line.matched ? &line : nullptr;
}

std::string GroundTruthReferenceOptions::Check() const {
  if (num_levels < 1) return "num_levels must be >= 1";
  if (!(gradient_threshold >= 0.0)) return "gradient_threshold must be >= 0";
  if (!(idepth_var > 0.0)) return "idepth_var must be > 0";
  if (!(max_block_idepth_spread > 0.0)) return "max_block_idepth_spread must be > 0";
  if (border < 1) return "border must be >= 1";
  if (!(edge_sample_spacing_px > 0.0)) return "edge_sample_spacing_px must be > 0";
  if (!(line_sigma_px > 0.0)) return "line_sigma_px must be > 0";
  if (!(line_noise_px >= 0.0)) return "line_noise_px must be >= 0";
  return "";
}

LineWithCovariance LineAtLevel(const LineWithCovariance& line_at_level0, int level) {
  const double s = static_cast<double>(1 << level);
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(2, 0) = (s - 1.0) / (2.0 * s);
  m(2, 1) = (s - 1.0) / (2.0 * s);
  m(2, 2) = 1.0 / s;
  LineWithCovariance result;
  result.line = m * line_at_level0.line;
  result.cov = m * line_at_level0.cov * m.transpose();
  return result;
}

Eigen::Vector2d PixelAtLevel(const Eigen::Vector2d& pixel_at_level0, int level) {
  const double s = static_cast<double>(1 << level);
  return (pixel_at_level0.array() + 0.5) / s - 0.5;
}

Eigen::Vector2d PixelAtLevel0(const Eigen::Vector2d& pixel_at_level, int level) {
  const double s = static_cast<double>(1 << level);
  return s * (pixel_at_level.array() + 0.5) - 0.5;
}

TrackingReference MakeReferenceFromDepth(const cv::Mat& image, const cv::Mat& depth,
                                         const PinholeCamera& camera,
                                         const GroundTruthReferenceOptions& options) {
  CheckInputs(image, depth, camera, options);
  const ImagePyramid pyramid(image, options.num_levels);
  TrackingReference reference;
  reference.levels.resize(pyramid.num_levels());
  for (int level = 0; level < pyramid.num_levels(); ++level) {
    TrackingReferenceLevel& out = reference.levels[level];
    out.camera = camera.AtLevel(level);
    const int s = 1 << level;
    const cv::Mat& data = pyramid.level(level);
    const double threshold_sq = options.gradient_threshold * options.gradient_threshold;
    for (int v = options.border; v < data.rows - options.border; ++v) {
      const float* row = data.ptr<float>(v);
      for (int u = options.border; u < data.cols - options.border; ++u) {
        const float* p = row + 3 * u;
        if (static_cast<double>(p[1]) * p[1] + static_cast<double>(p[2]) * p[2] <= threshold_sq) {
          continue;
        }
        double min_idepth = 1e300;
        double max_idepth = 0.0;
        double sum_idepth = 0.0;
        bool valid = true;
        // The block, grown by one level-0 pixel on every side for the consistency check (a
        // pixel on an occluding boundary mixes the intensities of two depths).
        const int x0 = std::max(0, s * u - 1);
        const int x1 = std::min(depth.cols - 1, s * u + s);
        const int y0 = std::max(0, s * v - 1);
        const int y1 = std::min(depth.rows - 1, s * v + s);
        for (int y = y0; y <= y1 && valid; ++y) {
          const float* depth_row = depth.ptr<float>(y);
          for (int x = x0; x <= x1; ++x) {
            if (!(depth_row[x] > 0.f)) {
              valid = false;
              break;
            }
            const double idepth = 1.0 / depth_row[x];
            min_idepth = std::min(min_idepth, idepth);
            max_idepth = std::max(max_idepth, idepth);
            if (x >= s * u && x < s * u + s && y >= s * v && y < s * v + s) sum_idepth += idepth;
          }
        }
        if (!valid) continue;
        const double mean_idepth = sum_idepth / (s * s);
        if (max_idepth - min_idepth > options.max_block_idepth_spread * mean_idepth) continue;
        ReferencePoint point;
        point.pixel = Eigen::Vector2d(u, v);
        point.idepth = mean_idepth;
        point.idepth_var = options.idepth_var;
        point.intensity = p[0];
        out.points.push_back(point);
      }
    }
  }
  return reference;
}

int AddGroundTruthEdges(const cv::Mat& image, const cv::Mat& depth,
                        const std::vector<EdgeSegment>& segments, const SE3& cur_from_ref,
                        const GroundTruthReferenceOptions& options, TrackingReference* reference) {
  if (reference->levels.empty()) {
    throw std::invalid_argument(Where(__LINE__) + "reference has no levels");
  }
  const PinholeCamera& camera = reference->levels[0].camera;
  CheckInputs(image, depth, camera, options);
  const ImagePyramid pyramid(image, reference->num_levels());
  std::mt19937 rng(static_cast<unsigned>(options.line_noise_seed));
  std::normal_distribution<double> gaussian(0.0, 1.0);
  int edges_with_points = 0;
  for (const EdgeSegment& segment : segments) {
    Eigen::Vector3d a = segment.start_in_ref;
    Eigen::Vector3d b = segment.end_in_ref;
    if (!ClipToDepth(&a, &b, kMinDepth)) continue;

    // The matched current line: the projection of the segment with the GT pose.
    MatchedLine matched_level0;
    Eigen::Vector3d a_cur = cur_from_ref * a;
    Eigen::Vector3d b_cur = cur_from_ref * b;
    if (ClipToDepth(&a_cur, &b_cur, kMinDepth)) {
      Eigen::Vector2d p1, p2;
      if (ClipToImage(camera.Project(a_cur), camera.Project(b_cur), camera.width, camera.height,
                      &p1, &p2) &&
          (p2 - p1).norm() >= kMinMatchedLength) {
        if (options.line_noise_px > 0.0) {
          p1 += options.line_noise_px * DrawVector2(gaussian, rng);
          p2 += options.line_noise_px * DrawVector2(gaussian, rng);
        }
        matched_level0.matched = true;
        matched_level0.line_in_cur = FitLine(p1, p2, options.line_sigma_px);
      }
    }

    const int edge_id = static_cast<int>(reference->levels[0].lines_in_cur.size());
    bool has_points = false;
    for (int level = 0; level < reference->num_levels(); ++level) {
      TrackingReferenceLevel& out = reference->levels[level];
      MatchedLine matched = matched_level0;
      if (matched.matched) matched.line_in_cur = LineAtLevel(matched_level0.line_in_cur, level);
      out.lines_in_cur.push_back(matched);

      const Eigen::Vector2d pa = out.camera.Project(a);
      const Eigen::Vector2d pb = out.camera.Project(b);
      const int samples =
          static_cast<int>(std::ceil((pb - pa).norm() / options.edge_sample_spacing_px)) + 1;
      for (int k = 0; k < samples; ++k) {
        // Uniform in the image: the 3D parameter t of image fraction sigma is
        // t = sigma z_a / (sigma z_a + (1 - sigma) z_b).
        const double sigma = samples == 1 ? 0.5 : static_cast<double>(k) / (samples - 1);
        const double t = sigma * a.z() / (sigma * a.z() + (1.0 - sigma) * b.z());
        const Eigen::Vector3d point_in_ref = a + t * (b - a);
        const Eigen::Vector2d pixel = out.camera.Project(point_in_ref);
        if (!out.camera.IsInside(pixel, options.border) ||
            !pyramid.CanSample(level, pixel.x(), pixel.y())) {
          continue;
        }
        if (!VisibleInDepth(depth, camera.Project(point_in_ref), point_in_ref.z())) continue;
        ReferencePoint point;
        point.pixel = pixel;
        point.idepth = 1.0 / point_in_ref.z();
        point.idepth_var = options.idepth_var;
        point.intensity = pyramid.SampleIntensity(level, pixel.x(), pixel.y());
        point.edge_id = edge_id;
        point.pixel_on_edge = pixel;  // sampled on the projected edge
        out.points.push_back(point);
        if (level == 0) has_points = true;
      }
    }
    if (has_points) ++edges_with_points;
  }
  return edges_with_points;
}

}  // namespace pldvo
