#include "experiments/evaluation/line_match_ground_truth.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace pldvo {
namespace {

// The smallest positive depth in the window around p, or 0.
float NearestDepth(const cv::Mat& depth, const Eigen::Vector2d& p, int radius) {
  const int x0 = static_cast<int>(std::lround(p.x()));
  const int y0 = static_cast<int>(std::lround(p.y()));
  float z = 0.f;
  for (int y = std::max(0, y0 - radius); y <= std::min(depth.rows - 1, y0 + radius); ++y) {
    for (int x = std::max(0, x0 - radius); x <= std::min(depth.cols - 1, x0 + radius); ++x) {
      const float d = depth.at<float>(y, x);
      if (d > 0.f && (z == 0.f || d < z)) z = d;
    }
  }
  return z;
}

}  // namespace

bool TransferPixelByDepth(const PinholeCamera& camera, const cv::Mat& ref_depth,
                          const SE3& cur_from_ref, const Eigen::Vector2d& pixel_in_ref,
                          int window_radius_px, Eigen::Vector2d* pixel_in_cur) {
  if (ref_depth.type() != CV_32F || ref_depth.cols != camera.width ||
      ref_depth.rows != camera.height) {
    throw std::invalid_argument("TransferPixelByDepth: depth must be CV_32F of the camera's size");
  }
  const float z = NearestDepth(ref_depth, pixel_in_ref, window_radius_px);
  if (z <= 0.f) return false;
  const Eigen::Vector3d point_in_cur = cur_from_ref * (z * camera.Unproject(pixel_in_ref));
  if (point_in_cur.z() <= 0.05) return false;
  *pixel_in_cur = camera.Project(point_in_cur);
  return true;
}

SegmentPredictor PredictorFromDepth(const PinholeCamera& camera, const cv::Mat& ref_depth,
                                    const SE3& cur_from_ref, int window_radius_px) {
  return [=](const LineSegment& s, Eigen::Vector2d* start, Eigen::Vector2d* end) {
    return TransferPixelByDepth(camera, ref_depth, cur_from_ref, s.start, window_radius_px,
                                start) &&
           TransferPixelByDepth(camera, ref_depth, cur_from_ref, s.end, window_radius_px, end);
  };
}

LineMatchTruth JudgeLineMatchByDepth(const PinholeCamera& camera, const LineSegment& ref,
                                     const cv::Mat& ref_depth, const SE3& cur_from_ref,
                                     const LineSegment& cur, const LineMatchTruthOptions& options) {
  const int n = std::max(2, static_cast<int>(ref.length / options.sample_step_px));
  std::vector<Eigen::Vector2d> projected;
  for (int i = 0; i <= n; ++i) {
    const Eigen::Vector2d p = ref.start + (ref.end - ref.start) * (static_cast<double>(i) / n);
    Eigen::Vector2d q;
    if (TransferPixelByDepth(camera, ref_depth, cur_from_ref, p, options.window_radius_px, &q) &&
        camera.IsInside(q, 0.0)) {
      projected.push_back(q);
    }
  }
  if (projected.size() < 3 || projected.size() < options.min_projected_fraction * (n + 1)) {
    return LineMatchTruth::kUnverifiable;
  }
  const auto agreeing = std::count_if(projected.begin(), projected.end(), [&](const auto& q) {
    return std::abs(cur.SignedDistance(q)) <= options.max_distance_px;
  });
  return agreeing >= options.min_agreeing_fraction * projected.size() ? LineMatchTruth::kCorrect
                                                                      : LineMatchTruth::kWrong;
}

}  // namespace pldvo
