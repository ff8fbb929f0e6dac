#include "backend/reference_builder.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "residuals/covariance_models.h"

namespace pldvo {
namespace {

// Per-pixel sums of one level over the level-0 hypotheses of its block.
struct LevelSums {
  int width = 0;
  int height = 0;
  std::vector<double> weighted_idepth;  // sum idepth_i / V_i
  std::vector<double> weight;           // sum 1 / V_i
  std::vector<int> count;               // n
  std::vector<int> edge_id;
  std::vector<double> edge_weight;  // 1 / V of the pixel that gave edge_id

  void Resize(int w, int h) {
    width = w;
    height = h;
    const size_t n = static_cast<size_t>(w) * h;
    weighted_idepth.assign(n, 0.0);
    weight.assign(n, 0.0);
    count.assign(n, 0);
    edge_id.assign(n, -1);
    edge_weight.assign(n, 0.0);
  }
};

// Keeps max_points evenly spaced entries of `points` (raster order), index floor(k n / max).
void ThinEvenly(int max_points, std::vector<ReferencePoint>* points) {
  const size_t n = points->size();
  if (max_points <= 0 || n <= static_cast<size_t>(max_points)) return;
  const size_t kept = static_cast<size_t>(max_points);
  for (size_t k = 0; k < kept; ++k) (*points)[k] = (*points)[k * n / kept];
  points->resize(kept);
}

// The foot point of `pixel` on the level-0 line `line_at_level0` expressed at `level`; `pixel`
// itself when the line is unknown (zero).
Eigen::Vector2d FootPoint(const Eigen::Vector2d& pixel, const Eigen::Vector3d& line_at_level0,
                          int level) {
  if (!(line_at_level0.head<2>().squaredNorm() > 0.0)) return pixel;
  LineWithCovariance line;
  line.line = line_at_level0;
  const Eigen::Vector3d l = LineAtLevel(line, level).line;
  return pixel - (l.head<2>().dot(pixel) + l.z()) * l.head<2>();
}

void AddPoints(const LevelSums& sums, const ImagePyramid& keyframe,
               const std::vector<Eigen::Vector3d>& keyframe_lines, int level,
               TrackingReferenceLevel* out) {
  const cv::Mat& image = keyframe.level(level);
  out->points.reserve(out->points.size() + sums.width * sums.height / 8);
  for (int y = 0; y < sums.height; ++y) {
    const float* row = image.ptr<float>(y);
    for (int x = 0; x < sums.width; ++x) {
      const int i = y * sums.width + x;
      if (sums.count[i] == 0 || !(sums.weight[i] > 0.0)) continue;
      ReferencePoint point;
      point.pixel = Eigen::Vector2d(x, y);
      point.idepth = sums.weighted_idepth[i] / sums.weight[i];
      point.idepth_var = sums.count[i] / sums.weight[i];
      point.intensity = row[3 * x];
      point.edge_id = sums.edge_id[i];
      point.pixel_on_edge =
          point.edge_id >= 0 && point.edge_id < static_cast<int>(keyframe_lines.size())
              ? FootPoint(point.pixel, keyframe_lines[point.edge_id], level)
              : point.pixel;
      out->points.push_back(point);
    }
  }
}

}  // namespace

TrackingReference BuildReferencePoints(const SemiDenseDepthMap& map, const ImagePyramid& keyframe,
                                       const PinholeCamera& camera, int max_points_per_level,
                                       const std::vector<Eigen::Vector3d>& keyframe_lines) {
  if (keyframe.num_levels() < 1 || map.width() != keyframe.width(0) ||
      map.height() != keyframe.height(0) || camera.width != map.width() ||
      camera.height != map.height()) {
    throw std::invalid_argument(std::string(__FILE__) +
                                ": BuildReferencePoints: map, keyframe and camera sizes differ");
  }
  TrackingReference reference;
  reference.levels.resize(keyframe.num_levels());
  LevelSums sums;
  sums.Resize(map.width(), map.height());
  for (int i = 0; i < map.num_pixels(); ++i) {
    if (!map.valid(i)) continue;
    const double idepth = map.idepth(i);
    const double var = map.idepth_var(i);
    if (!(idepth >= 0.0) || !(var > 0.0)) continue;
    sums.weighted_idepth[i] = idepth / var;
    sums.weight[i] = 1.0 / var;
    sums.count[i] = 1;
    if (map.edge_id(i) >= 0) {
      sums.edge_id[i] = map.edge_id(i);
      sums.edge_weight[i] = 1.0 / var;
    }
  }
  for (int level = 0; level < keyframe.num_levels(); ++level) {
    TrackingReferenceLevel& out = reference.levels[level];
    out.camera = camera.AtLevel(level);
    if (level > 0) {
      // Aggregate the 2x2 children of the finer level (its sums are over level-0 pixels).
      LevelSums coarse;
      coarse.Resize(keyframe.width(level), keyframe.height(level));
      for (int y = 0; y < coarse.height; ++y) {
        for (int x = 0; x < coarse.width; ++x) {
          const int i = y * coarse.width + x;
          for (int dy = 0; dy < 2; ++dy) {
            for (int dx = 0; dx < 2; ++dx) {
              const int cx = 2 * x + dx, cy = 2 * y + dy;
              if (cx >= sums.width || cy >= sums.height) continue;
              const int c = cy * sums.width + cx;
              if (sums.count[c] == 0) continue;
              coarse.weighted_idepth[i] += sums.weighted_idepth[c];
              coarse.weight[i] += sums.weight[c];
              coarse.count[i] += sums.count[c];
              if (sums.edge_id[c] >= 0 && sums.edge_weight[c] > coarse.edge_weight[i]) {
                coarse.edge_id[i] = sums.edge_id[c];
                coarse.edge_weight[i] = sums.edge_weight[c];
              }
            }
          }
        }
      }
      sums = std::move(coarse);
    }
    AddPoints(sums, keyframe, keyframe_lines, level, &out);
    ThinEvenly(max_points_per_level, &out.points);
  }
  return reference;
}

std::vector<MatchedLine> MatchedLinesFromMatches(const std::vector<LineMatch>& matches,
                                                 const std::vector<LineSegment>& cur_segments,
                                                 int num_keyframe_segments) {
  std::vector<MatchedLine> lines(std::max(0, num_keyframe_segments));
  for (const LineMatch& match : matches) {
    if (match.ref_index < 0 || match.ref_index >= num_keyframe_segments || match.cur_index < 0 ||
        match.cur_index >= static_cast<int>(cur_segments.size())) {
      continue;
    }
    const LineSegment& segment = cur_segments[match.cur_index];
    MatchedLine& line = lines[match.ref_index];
    line.matched = true;
    line.line_in_cur.line = segment.line;
    line.line_in_cur.cov = segment.line_cov;
  }
  return lines;
}

void SetMatchedLines(const std::vector<MatchedLine>& lines_at_level0,
                     TrackingReference* reference) {
  for (int level = 0; level < reference->num_levels(); ++level) {
    TrackingReferenceLevel& ref = reference->levels[level];
    // Every edge id of the level's points needs an entry (unmatched when the frame has none).
    size_t size = lines_at_level0.size();
    for (const ReferencePoint& point : ref.points) {
      size = std::max(size, static_cast<size_t>(point.edge_id + 1));
    }
    std::vector<MatchedLine>& lines = ref.lines_in_cur;
    lines.assign(size, MatchedLine());
    for (size_t e = 0; e < lines_at_level0.size(); ++e) {
      lines[e].matched = lines_at_level0[e].matched;
      if (lines[e].matched)
        lines[e].line_in_cur = LineAtLevel(lines_at_level0[e].line_in_cur, level);
    }
  }
}

int RemoveLineOutliers(const SE3& cur_from_ref, double max_median_px, TrackingReference* reference,
                       std::vector<MatchedLine>* lines_at_level0) {
  if (reference->num_levels() == 0) return 0;
  const TrackingReferenceLevel& level0 = reference->levels[0];
  const int num_edges = static_cast<int>(level0.lines_in_cur.size());
  std::vector<std::vector<double>> distances(num_edges);
  for (const ReferencePoint& point : level0.points) {
    if (point.edge_id < 0 || point.edge_id >= num_edges ||
        !level0.lines_in_cur[point.edge_id].matched) {
      continue;
    }
    Eigen::Vector2d pixel_cur;
    if (!Reproject(level0.camera, cur_from_ref, point.pixel_on_edge, point.idepth, &pixel_cur)) {
      continue;
    }
    const Eigen::Vector3d& l = level0.lines_in_cur[point.edge_id].line_in_cur.line;
    distances[point.edge_id].push_back(
        std::abs(l.x() * pixel_cur.x() + l.y() * pixel_cur.y() + l.z()));
  }
  int removed = 0;
  for (int e = 0; e < num_edges; ++e) {
    std::vector<double>& d = distances[e];
    if (d.empty()) continue;
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    if (d[d.size() / 2] <= max_median_px) continue;
    ++removed;
    for (TrackingReferenceLevel& level : reference->levels) {
      if (e < static_cast<int>(level.lines_in_cur.size())) level.lines_in_cur[e].matched = false;
    }
    if (lines_at_level0 != nullptr && e < static_cast<int>(lines_at_level0->size())) {
      (*lines_at_level0)[e].matched = false;
    }
  }
  return removed;
}

double MeanInverseDepth(const SemiDenseDepthMap& map) {
  double sum = 0.0;
  int count = 0;
  for (int i = 0; i < map.num_pixels(); ++i) {
    if (!map.valid(i)) continue;
    sum += map.idepth(i);
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

double ReferenceOverlap(const TrackingReference& reference, int level, const SE3& cur_from_ref) {
  if (level < 0 || level >= reference.num_levels()) return 1.0;
  const TrackingReferenceLevel& ref = reference.levels[level];
  if (ref.points.empty()) return 1.0;
  int inside = 0;
  for (const ReferencePoint& point : ref.points) {
    Eigen::Vector2d pixel_cur;
    if (Reproject(ref.camera, cur_from_ref, point.pixel, point.idepth, &pixel_cur) &&
        ref.camera.IsInside(pixel_cur, 0.0)) {
      ++inside;
    }
  }
  return static_cast<double>(inside) / ref.points.size();
}

}  // namespace pldvo
