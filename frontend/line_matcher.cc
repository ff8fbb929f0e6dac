#include "frontend/line_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <string>

#include "frontend/lbd_describer.h"

namespace pldvo {
namespace {

int AngleBin(double angle, int num_bins) {
  double a = std::fmod(angle, 2.0 * M_PI);
  if (a < 0.0) a += 2.0 * M_PI;
  return std::min(num_bins - 1, static_cast<int>(a / (2.0 * M_PI) * num_bins));
}

void CheckDescriptors(const cv::Mat& descriptors, size_t num_segments, const char* which) {
  if (descriptors.rows != static_cast<int>(num_segments) ||
      (num_segments > 0 && (descriptors.cols != 32 || descriptors.type() != CV_8U))) {
    throw std::invalid_argument(std::string(__FILE__) + ": " + which +
                                " descriptors must be a segments.size() x 32 CV_8U matrix");
  }
}

}  // namespace

SegmentPredictor PredictorFromHomography(const Eigen::Matrix3d& cur_from_ref) {
  return [cur_from_ref](const LineSegment& segment, Eigen::Vector2d* start, Eigen::Vector2d* end) {
    const Eigen::Vector3d s = cur_from_ref * segment.start.homogeneous();
    const Eigen::Vector3d e = cur_from_ref * segment.end.homogeneous();
    if (s.z() <= 1e-12 || e.z() <= 1e-12) return false;
    *start = s.hnormalized();
    *end = e.hnormalized();
    return true;
  };
}

LineMatcher::LineMatcher(const LineMatcherOptions& options) : options_(options) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument("LineMatcherOptions: " + error);
}

std::vector<LineMatch> LineMatcher::Match(const std::vector<LineSegment>& ref_segments,
                                          const cv::Mat& ref_descriptors,
                                          const std::vector<LineSegment>& cur_segments,
                                          const cv::Mat& cur_descriptors,
                                          const SegmentPredictor& predictor) const {
  return Select(Gate(ref_segments, cur_segments, predictor), ref_descriptors, cur_descriptors,
                cur_segments.size());
}

std::vector<std::vector<int>> LineMatcher::Gate(const std::vector<LineSegment>& ref_segments,
                                                const std::vector<LineSegment>& cur_segments,
                                                const SegmentPredictor& predictor) const {
  std::vector<std::vector<int>> gated(ref_segments.size());
  if (ref_segments.empty() || cur_segments.empty()) return gated;

  // Bucket grid over the current segments' bounding box; a segment is entered in every cell
  // its body passes through.
  const double cell = options_.cell_size_px;
  const int num_bins = options_.num_angle_bins;
  Eigen::Vector2d lo = cur_segments[0].start, hi = lo;
  for (const LineSegment& s : cur_segments) {
    lo = lo.cwiseMin(s.start).cwiseMin(s.end);
    hi = hi.cwiseMax(s.start).cwiseMax(s.end);
  }
  const int cells_x = static_cast<int>((hi.x() - lo.x()) / cell) + 1;
  const int cells_y = static_cast<int>((hi.y() - lo.y()) / cell) + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(cells_x) * cells_y * num_bins);
  for (int c = 0; c < static_cast<int>(cur_segments.size()); ++c) {
    const LineSegment& s = cur_segments[c];
    const int bin = AngleBin(s.angle, num_bins);
    const int steps = static_cast<int>(s.length / (0.5 * cell)) + 1;
    size_t last = SIZE_MAX;
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = s.start + (s.end - s.start) * (static_cast<double>(k) / steps);
      const int cx = std::clamp(static_cast<int>((p.x() - lo.x()) / cell), 0, cells_x - 1);
      const int cy = std::clamp(static_cast<int>((p.y() - lo.y()) / cell), 0, cells_y - 1);
      const size_t index = (static_cast<size_t>(cy) * cells_x + cx) * num_bins + bin;
      if (index == last) continue;
      last = index;
      if (buckets[index].empty() || buckets[index].back() != c) buckets[index].push_back(c);
    }
  }

  const bool predicted = static_cast<bool>(predictor);
  const double radius = predicted ? options_.predicted_radius_px : options_.search_radius_px;
  const double max_angle =
      (predicted ? options_.predicted_max_angle_deg : options_.max_angle_deg) * M_PI / 180.0;
  const int bin_reach = std::min((num_bins - 1) / 2,
                                 static_cast<int>(std::ceil(max_angle / (2.0 * M_PI / num_bins))));
  std::vector<int> stamp(cur_segments.size(), -1);
  std::vector<int> candidates;

  for (int r = 0; r < static_cast<int>(ref_segments.size()); ++r) {
    const LineSegment& ref = ref_segments[r];
    Eigen::Vector2d start = ref.start, end = ref.end;
    if (predicted && !predictor(ref, &start, &end)) continue;
    const double length = (end - start).norm();
    if (length < 1e-6) continue;
    const Eigen::Vector2d direction = (end - start) / length;
    const Eigen::Vector2d normal(-direction.y(), direction.x());
    const double angle = std::atan2(direction.y(), direction.x());

    // Candidates from the buckets covering the grown bounding box.
    candidates.clear();
    const Eigen::Vector2d box_lo = start.cwiseMin(end).array() - radius;
    const Eigen::Vector2d box_hi = start.cwiseMax(end).array() + radius;
    const int cx0 = std::max(0, static_cast<int>(std::floor((box_lo.x() - lo.x()) / cell)));
    const int cy0 = std::max(0, static_cast<int>(std::floor((box_lo.y() - lo.y()) / cell)));
    const int cx1 =
        std::min(cells_x - 1, static_cast<int>(std::floor((box_hi.x() - lo.x()) / cell)));
    const int cy1 =
        std::min(cells_y - 1, static_cast<int>(std::floor((box_hi.y() - lo.y()) / cell)));
    const int ref_bin = AngleBin(angle, num_bins);
    for (int cy = cy0; cy <= cy1; ++cy) {
      for (int cx = cx0; cx <= cx1; ++cx) {
        for (int db = -bin_reach; db <= bin_reach; ++db) {
          const int bin = ((ref_bin + db) % num_bins + num_bins) % num_bins;
          for (int c : buckets[(static_cast<size_t>(cy) * cells_x + cx) * num_bins + bin]) {
            if (stamp[c] == r) continue;
            stamp[c] = r;
            candidates.push_back(c);
          }
        }
      }
    }

    for (int c : candidates) {
      const LineSegment& cur = cur_segments[c];
      if (AngleDifference(cur.angle, angle) > max_angle) continue;
      if (std::abs(normal.dot(cur.midpoint() - start)) > radius) continue;
      const double a = direction.dot(cur.start - start);
      const double b = direction.dot(cur.end - start);
      if (std::max(a, b) < -radius || std::min(a, b) > length + radius) continue;
      gated[r].push_back(c);
    }
  }
  return gated;
}

std::vector<LineMatch> LineMatcher::Select(const std::vector<std::vector<int>>& gated,
                                           const cv::Mat& ref_descriptors,
                                           const cv::Mat& cur_descriptors,
                                           size_t num_cur_segments) const {
  CheckDescriptors(ref_descriptors, gated.size(), "reference");
  CheckDescriptors(cur_descriptors, num_cur_segments, "current");
  struct Best {
    int best = INT_MAX, second = INT_MAX, index = -1;
  };
  std::vector<Best> ref_best(gated.size());
  std::vector<Best> cur_best(num_cur_segments);  // best reference per current segment
  for (int r = 0; r < static_cast<int>(gated.size()); ++r) {
    const uint8_t* ref_row = ref_descriptors.ptr<uint8_t>(r);
    Best& best = ref_best[r];
    for (int c : gated[r]) {
      const int distance = HammingDistance32(ref_row, cur_descriptors.ptr<uint8_t>(c));
      if (distance < best.best) {
        best.second = best.best;
        best.best = distance;
        best.index = c;
      } else if (distance < best.second) {
        best.second = distance;
      }
      Best& back = cur_best[c];
      if (distance < back.best) {
        back.second = back.best;
        back.best = distance;
        back.index = r;
      } else if (distance < back.second) {
        back.second = distance;
      }
    }
  }

  std::vector<LineMatch> matches;
  for (int r = 0; r < static_cast<int>(gated.size()); ++r) {
    const Best& best = ref_best[r];
    if (best.index < 0 || best.best > options_.max_hamming) continue;
    if (best.second != INT_MAX && best.best >= options_.ratio * best.second) continue;
    if (options_.mutual && cur_best[best.index].index != r) continue;
    matches.push_back({r, best.index, best.best});
  }
  return matches;
}

}  // namespace pldvo
