#include "frontend/line_refiner.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace pldvo {
namespace {

constexpr int kMaxSearchRadius = 8;  // LineRefinerOptions::Check bounds search_radius_px

// Bilinear intensity at (x, y); the caller keeps (x, y) at least 1 px inside the image.
float Bilinear(const cv::Mat& gray, double x, double y) {
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  const float ax = static_cast<float>(x - x0);
  const float ay = static_cast<float>(y - y0);
  const uint8_t* row0 = gray.ptr<uint8_t>(y0) + x0;
  const uint8_t* row1 = gray.ptr<uint8_t>(y0 + 1) + x0;
  return (1.f - ay) * ((1.f - ax) * row0[0] + ax * row0[1]) +
         ay * ((1.f - ax) * row1[0] + ax * row1[1]);
}

// g(s) for s = -radius..radius at p (g[s + radius]); false when the profile leaves the image.
bool CrossProfile(const cv::Mat& gray, const Eigen::Vector2d& p, const Eigen::Vector2d& n,
                  int radius, float* g) {
  const double reach = radius + 0.5;
  for (const double s : {-reach, reach}) {
    const Eigen::Vector2d q = p + s * n;
    if (q.x() < 0.0 || q.y() < 0.0 || q.x() > gray.cols - 2 || q.y() > gray.rows - 2) {
      return false;
    }
  }
  float previous = Bilinear(gray, p.x() - reach * n.x(), p.y() - reach * n.y());
  for (int k = 0; k <= 2 * radius; ++k) {
    const double s = k - radius + 0.5;
    const float next = Bilinear(gray, p.x() + s * n.x(), p.y() + s * n.y());
    g[k] = next - previous;
    previous = next;
  }
  return true;
}

// One refit of the segment *start -> *end: its endpoints projected onto the line through the
// edge points of its cross-profiles. False with too few points.
bool RefitOnce(const cv::Mat& gray, const LineRefinerOptions& options, Eigen::Vector2d* start,
               Eigen::Vector2d* end) {
  const double step = options.sample_step_px;
  const int radius = options.search_radius_px;
  const int width = 2 * radius + 1;
  const double length = (*end - *start).norm();
  const int samples = static_cast<int>(std::floor((length - 2.0 * step) / step)) + 1;
  if (samples < 3) return false;
  const Eigen::Vector2d d = (*end - *start) / length;
  const Eigen::Vector2d n(-d.y(), d.x());
  std::vector<float> profiles(static_cast<size_t>(samples) * width);
  std::vector<char> inside(samples, 0);
  double polarity_sum = 0.0;
  for (int i = 0; i < samples; ++i) {
    float* g = &profiles[static_cast<size_t>(i) * width];
    inside[i] = CrossProfile(gray, *start + (step + i * step) * d, n, radius, g);
    if (inside[i]) polarity_sum += g[radius];
  }
  const float polarity = polarity_sum >= 0.0 ? 1.f : -1.f;
  std::vector<cv::Point2f> points;
  points.reserve(samples);
  for (int i = 0; i < samples; ++i) {
    if (!inside[i]) continue;
    float g[2 * kMaxSearchRadius + 1];
    for (int k = 0; k < width; ++k) g[k] = polarity * profiles[static_cast<size_t>(i) * width + k];
    const int best = static_cast<int>(std::max_element(g, g + width) - g);
    if (best == 0 || best == width - 1 || !(g[best] >= options.min_edge_step)) continue;
    // Centroid of the peak's three samples (clipped at 0): exact for the triangular profile of
    // a box-filtered step, where the parabola's vertex is biased by up to ~0.2 px.
    const double left = std::max(0.f, g[best - 1]), right = std::max(0.f, g[best + 1]);
    const double delta = (right - left) / (left + g[best] + right);
    const Eigen::Vector2d q = *start + (step + i * step) * d + (best - radius + delta) * n;
    points.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
  }
  if (points.size() < 3 || points.size() < options.min_point_fraction * samples) return false;
  cv::Vec4f fit;  // (vx, vy, x0, y0)
  cv::fitLine(points, fit, cv::DIST_L2, 0.0, 0.01, 0.01);
  const Eigen::Vector2d direction(fit[0], fit[1]);
  const Eigen::Vector2d origin(fit[2], fit[3]);
  *start = origin + direction.dot(*start - origin) * direction;
  *end = origin + direction.dot(*end - origin) * direction;
  return true;
}

bool RefineSegment(const cv::Mat& gray, const LineRefinerOptions& options, double endpoint_sigma_px,
                   LineSegment* segment) {
  // A few passes: a segment that starts up to search_radius_px off the edge at one end sees the
  // whole edge only from the second pass on.
  constexpr int kMaxPasses = 3;
  constexpr double kConvergedPx = 0.01;
  Eigen::Vector2d start = segment->start, end = segment->end;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    const Eigen::Vector2d previous_start = start, previous_end = end;
    if (!RefitOnce(gray, options, &start, &end)) return false;
    if ((start - previous_start).norm() < kConvergedPx &&
        (end - previous_end).norm() < kConvergedPx) {
      break;
    }
  }
  const Eigen::Vector2d direction = (end - start).normalized();
  if (std::acos(std::min(1.0, direction.dot(segment->direction()))) >
      options.max_angle_deg * M_PI / 180.0) {
    return false;
  }
  if ((0.5 * (start + end) - segment->midpoint()).norm() > options.max_shift_px) return false;
  *segment = MakeLineSegment(start, end, segment->octave,
                             endpoint_sigma_px * std::ldexp(1.0, segment->octave));
  return true;
}

}  // namespace

int RefineSegmentsToEdges(const cv::Mat& gray, const LineRefinerOptions& options,
                          double endpoint_sigma_px, std::vector<LineSegment>* segments) {
  if (gray.type() != CV_8UC1) {
    throw std::invalid_argument("RefineSegmentsToEdges: the image must be CV_8UC1");
  }
  int refined = 0;
  for (LineSegment& segment : *segments) {
    refined += RefineSegment(gray, options, endpoint_sigma_px, &segment);
  }
  return refined;
}

}  // namespace pldvo
