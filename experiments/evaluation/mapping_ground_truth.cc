#include "experiments/evaluation/mapping_ground_truth.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "core/random_draws.h"
#include "core/statistics.h"
#include "frontend/line_segment.h"
#include "residuals/covariance_models.h"

namespace pldvo {
namespace {

// Clips a segment to z >= near_z; false when it lies entirely in front of that plane.
bool ClipNear(Eigen::Vector3d* a, Eigen::Vector3d* b, double near_z) {
  if (a->z() < near_z && b->z() < near_z) return false;
  if (a->z() < near_z) *a = *b + (*a - *b) * ((b->z() - near_z) / (b->z() - a->z()));
  if (b->z() < near_z) *b = *a + (*b - *a) * ((a->z() - near_z) / (a->z() - b->z()));
  return true;
}

// Liang-Barsky clipping of p + s (q - p), s in [0, 1], to [0, w-1] x [0, h-1].
bool ClipToImage(Eigen::Vector2d* p, Eigen::Vector2d* q, int width, int height) {
  const Eigen::Vector2d d = *q - *p;
  double s0 = 0.0, s1 = 1.0;
  const double lo[2] = {0.0, 0.0}, hi[2] = {width - 1.0, height - 1.0};
  for (int c = 0; c < 2; ++c) {
    if (std::abs(d[c]) < 1e-12) {
      if ((*p)[c] < lo[c] || (*p)[c] > hi[c]) return false;
      continue;
    }
    double a = (lo[c] - (*p)[c]) / d[c], b = (hi[c] - (*p)[c]) / d[c];
    if (a > b) std::swap(a, b);
    s0 = std::max(s0, a);
    s1 = std::min(s1, b);
  }
  if (s0 > s1) return false;
  const Eigen::Vector2d start = *p + s0 * d, end = *p + s1 * d;
  *p = start;
  *q = end;
  return true;
}

bool ProjectSegment(const Eigen::Vector3d& start, const Eigen::Vector3d& end,
                    const PinholeCamera& camera, double near_z, Eigen::Vector2d* p,
                    Eigen::Vector2d* q) {
  Eigen::Vector3d a = start, b = end;
  if (!ClipNear(&a, &b, near_z)) return false;
  *p = camera.Project(a);
  *q = camera.Project(b);
  return ClipToImage(p, q, camera.width, camera.height);
}

}  // namespace

GroundTruthEdges MakeGroundTruthEdges(const std::vector<EdgeSegment>& segments_in_ref,
                                      const cv::Mat& depth, const PinholeCamera& camera,
                                      const GroundTruthEdgeOptions& options) {
  if (depth.type() != CV_32F || depth.cols != camera.width || depth.rows != camera.height) {
    throw std::invalid_argument("MakeGroundTruthEdges: depth must be CV_32F of the camera size");
  }
  GroundTruthEdges result;
  result.segments_in_ref = segments_in_ref;
  std::vector<LineSegment> segments(segments_in_ref.size());
  std::vector<int> ids;
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (size_t i = 0; i < segments_in_ref.size(); ++i) {
    Eigen::Vector2d p, q;
    if (!ProjectSegment(segments_in_ref[i].start_in_ref, segments_in_ref[i].end_in_ref, camera,
                        options.near_z, &p, &q)) {
      continue;
    }
    if ((q - p).norm() < options.min_length_px) continue;
    if (options.line_sigma_px > 0.0) {
      p += options.line_sigma_px * DrawVector2(noise, rng);
      q += options.line_sigma_px * DrawVector2(noise, rng);
    }
    segments[i] = MakeLineSegment(p, q, 0, options.line_sigma_px);
    ids.push_back(static_cast<int>(i));
  }
  EdgeTracerOptions tracer_options;
  tracer_options.half_width_px = options.half_width_px;
  tracer_options.border_px = options.border_px;
  const EdgeTracer tracer(tracer_options);
  result.trace = tracer.Trace(segments, ids, cv::Size(camera.width, camera.height));
  result.line_idepth = cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(0.f));
  result.centre_mask = cv::Mat(camera.height, camera.width, CV_8U, cv::Scalar(0));
  for (TracedLine& line : result.trace.lines) {
    const EdgeSegment& segment = segments_in_ref[line.id];
    const Eigen::Vector3d origin = segment.start_in_ref;
    const Eigen::Vector3d direction = segment.end_in_ref - segment.start_in_ref;
    std::vector<Eigen::Vector2i> kept;
    for (const Eigen::Vector2i& pixel : line.pixels) {
      // Closest point of the 3D line to the pixel's ray t r: solve for (t, s).
      const Eigen::Vector3d r = camera.Unproject(pixel.cast<double>());
      Eigen::Matrix2d a;
      a << r.dot(r), -r.dot(direction), r.dot(direction), -direction.dot(direction);
      const Eigen::Vector2d rhs(r.dot(origin), direction.dot(origin));
      const double det = a.determinant();
      bool visible = false;
      double z_line = 0.0;
      if (std::abs(det) > 1e-12) {
        const Eigen::Vector2d ts = a.inverse() * rhs;
        const double s = ts.y();
        z_line = (origin + s * direction).z();
        if (s >= -0.02 && s <= 1.02 && z_line > options.near_z) {
          for (int dy = -1; dy <= 1 && !visible; ++dy) {
            for (int dx = -1; dx <= 1 && !visible; ++dx) {
              const int x = pixel.x() + dx, y = pixel.y() + dy;
              if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) continue;
              const float z = depth.at<float>(y, x);
              visible = z > 0.f && std::abs(z - z_line) <= options.max_depth_rel_diff * z_line;
            }
          }
        }
      }
      if (!visible) {
        result.trace.id_map.at<int32_t>(pixel.y(), pixel.x()) = -1;
        continue;
      }
      kept.push_back(pixel);
      result.line_idepth.at<float>(pixel.y(), pixel.x()) = static_cast<float>(1.0 / z_line);
      if (std::abs(line.segment.SignedDistance(pixel.cast<double>())) <= 0.5) {
        result.centre_mask.at<uint8_t>(pixel.y(), pixel.x()) = 255;
      }
    }
    line.pixels = kept;
  }
  return result;
}

std::vector<MatchedLine> ProjectGroundTruthLines(const GroundTruthEdges& edges,
                                                 const PinholeCamera& camera,
                                                 const SE3& cur_from_ref, double sigma_px,
                                                 uint32_t seed) {
  std::vector<MatchedLine> lines(edges.segments_in_ref.size());
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (const TracedLine& line : edges.trace.lines) {
    const EdgeSegment& segment = edges.segments_in_ref[line.id];
    Eigen::Vector2d p, q;
    if (!ProjectSegment(cur_from_ref * segment.start_in_ref, cur_from_ref * segment.end_in_ref,
                        camera, 0.05, &p, &q)) {
      continue;
    }
    if ((q - p).norm() < 10.0) continue;
    if (sigma_px > 0.0) {
      p += DrawVector2(noise, rng);
      q += DrawVector2(noise, rng);
    }
    lines[line.id].matched = true;
    lines[line.id].line_in_cur = FitLine(p, q, std::max(sigma_px, 1e-3));
  }
  return lines;
}

cv::Mat InverseDepthFromDepth(const cv::Mat& depth) {
  cv::Mat result(depth.rows, depth.cols, CV_32F, cv::Scalar(0.f));
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      const float z = depth.at<float>(y, x);
      if (z > 0.f) result.at<float>(y, x) = 1.f / z;
    }
  }
  return result;
}

DepthErrorStats EvaluateDepthMap(const SemiDenseDepthMap& map, const cv::Mat& gt_idepth,
                                 const cv::Mat& mask, bool require_observed, double scale) {
  if (gt_idepth.type() != CV_32F || gt_idepth.cols != map.width() ||
      gt_idepth.rows != map.height()) {
    throw std::invalid_argument("EvaluateDepthMap: gt_idepth must be CV_32F of the map's size");
  }
  if (!(scale > 0.0)) throw std::invalid_argument("EvaluateDepthMap: scale must be > 0");
  std::vector<double> rel, nees;
  int within = 0;
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const int i = map.Index(x, y);
      if (!map.valid(i) || (require_observed && map.num_observations(i) == 0)) continue;
      if (!mask.empty() && mask.at<uint8_t>(y, x) == 0) continue;
      const double gt = gt_idepth.at<float>(y, x);
      if (!(gt > 0.0)) continue;
      const double error = scale * map.idepth(i) - gt;
      const double var = scale * scale * map.idepth_var(i);
      rel.push_back(std::abs(error) / gt);
      nees.push_back(error * error / var);
      within += (error * error <= 4.0 * var);
    }
  }
  DepthErrorStats stats;
  stats.count = static_cast<int>(rel.size());
  if (rel.empty()) return stats;
  stats.median_rel_error = Median(rel);
  stats.median_nees = Median(nees);
  for (size_t k = 0; k < rel.size(); ++k) {
    stats.mean_rel_error += rel[k] / rel.size();
    stats.mean_nees += nees[k] / nees.size();
  }
  stats.within_2sigma = static_cast<double>(within) / rel.size();
  int bulk = 0;
  for (const double e : nees) {
    if (e > kGrossNees) continue;
    stats.bulk_mean_nees += e;
    ++bulk;
  }
  stats.gross_fraction = 1.0 - static_cast<double>(bulk) / nees.size();
  if (bulk > 0) stats.bulk_mean_nees /= bulk;
  return stats;
}

double MedianInverseDepthRatio(const SemiDenseDepthMap& map, const cv::Mat& gt_idepth,
                               bool require_observed) {
  if (gt_idepth.type() != CV_32F || gt_idepth.cols != map.width() ||
      gt_idepth.rows != map.height()) {
    throw std::invalid_argument(
        "MedianInverseDepthRatio: gt_idepth must be CV_32F of the map's size");
  }
  std::vector<double> ratios;
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const int i = map.Index(x, y);
      if (!map.valid(i) || (require_observed && map.num_observations(i) == 0)) continue;
      const double gt = gt_idepth.at<float>(y, x);
      if (gt > 0.0 && map.idepth(i) > 0.0) ratios.push_back(gt / map.idepth(i));
    }
  }
  return Median(std::move(ratios));  // 0 when no pixel has both depths
}

cv::Mat ContinuousDepthMask(const cv::Mat& gt_idepth, int radius, double max_rel_step) {
  if (gt_idepth.type() != CV_32F || radius < 0 || !(max_rel_step > 0.0)) {
    throw std::invalid_argument("ContinuousDepthMask: CV_32F input, radius >= 0, step > 0");
  }
  cv::Mat step(gt_idepth.size(), CV_8U, cv::Scalar(0));
  auto jumps = [&](float a, float b) {
    return !(a > 0.f && b > 0.f) || std::abs(a - b) > max_rel_step * std::min(a, b);
  };
  for (int y = 0; y < gt_idepth.rows; ++y) {
    for (int x = 0; x < gt_idepth.cols; ++x) {
      const float g = gt_idepth.at<float>(y, x);
      if (x + 1 < gt_idepth.cols && jumps(g, gt_idepth.at<float>(y, x + 1))) {
        step.at<uint8_t>(y, x) = step.at<uint8_t>(y, x + 1) = 255;
      }
      if (y + 1 < gt_idepth.rows && jumps(g, gt_idepth.at<float>(y + 1, x))) {
        step.at<uint8_t>(y, x) = step.at<uint8_t>(y + 1, x) = 255;
      }
    }
  }
  cv::Mat near_step;
  cv::dilate(step, near_step,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * radius + 1, 2 * radius + 1)));
  cv::Mat mask;
  cv::bitwise_not(near_step, mask);
  return mask;
}

}  // namespace pldvo
