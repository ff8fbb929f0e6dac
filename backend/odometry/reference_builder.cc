#include "backend/odometry/reference_builder.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/statistics.h"
#include "residuals/covariance_models.h"

namespace pldvo {
namespace {

// Per-pixel sums of one level over the level-0 hypotheses of its block.
struct LevelSums {
  int width = 0;
  int height = 0;
  std::vector<double> weighted_idepths;  // sum idepth_i / V_i
  std::vector<double> weights;           // sum 1 / V_i
  std::vector<int> counts;               // n
  std::vector<int> edge_ids;
  std::vector<double> edge_weights;  // 1 / V of the pixel that gave edge_id

  LevelSums(int w, int h) : width(w), height(h) {
    const size_t n = static_cast<size_t>(w) * h;
    weighted_idepths.assign(n, 0.0);
    weights.assign(n, 0.0);
    counts.assign(n, 0);
    edge_ids.assign(n, -1);
    edge_weights.assign(n, 0.0);
  }
  double weighted_idepth(int i) const { return weighted_idepths[i]; }
  double weight(int i) const { return weights[i]; }
  int count(int i) const { return counts[i]; }
  int edge_id(int i) const { return edge_ids[i]; }
  double edge_weight(int i) const { return edge_weights[i]; }
};

// Level 0: the map's hypotheses as one-hypothesis sums, read in place (no level-sized copy).
struct MapSums {
  const SemiDenseDepthMap& map;
  int width;
  int height;

  explicit MapSums(const SemiDenseDepthMap& m) : map(m), width(m.width()), height(m.height()) {}
  int count(int i) const {
    if (!map.valid(i)) return 0;
    const double idepth = map.idepth(i), var = map.idepth_var(i);
    return idepth >= 0.0 && var > 0.0 ? 1 : 0;
  }
  double weighted_idepth(int i) const {
    return static_cast<double>(map.idepth(i)) / static_cast<double>(map.idepth_var(i));
  }
  double weight(int i) const { return 1.0 / static_cast<double>(map.idepth_var(i)); }
  int edge_id(int i) const { return map.edge_id(i); }  // -1: on no edge
  double edge_weight(int i) const { return map.edge_id(i) >= 0 ? weight(i) : 0.0; }
};

// The sums of the next coarser level (w x h): each pixel aggregates its 2x2 children of `fine`.
template <class Sums>
LevelSums Aggregate(const Sums& fine, int w, int h) {
  LevelSums coarse(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int cx = 2 * x + dx, cy = 2 * y + dy;
          if (cx >= fine.width || cy >= fine.height) continue;
          const int c = cy * fine.width + cx;
          if (fine.count(c) == 0) continue;
          coarse.weighted_idepths[i] += fine.weighted_idepth(c);
          coarse.weights[i] += fine.weight(c);
          coarse.counts[i] += fine.count(c);
          if (fine.edge_id(c) >= 0 && fine.edge_weight(c) > coarse.edge_weights[i]) {
            coarse.edge_ids[i] = fine.edge_id(c);
            coarse.edge_weights[i] = fine.edge_weight(c);
          }
        }
      }
    }
  }
  return coarse;
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

// Adds the level's points in raster order; with max_points > 0 and more candidates n than that,
// only max_points evenly spaced ones: candidate ordinals floor(k n / max_points), k = 0, 1, ...
// (so a thinned level costs one pass, and no point is built only to be dropped).
template <class Sums>
void AddPoints(const Sums& sums, const ImagePyramid& keyframe,
               const std::vector<Eigen::Vector3d>& keyframe_lines, int level, int max_points,
               TrackingReferenceLevel* out) {
  const auto is_candidate = [&sums](int i) { return sums.count(i) > 0 && sums.weight(i) > 0.0; };
  size_t n = 0;
  for (int i = 0; i < sums.width * sums.height; ++i) n += is_candidate(i);
  const size_t kept = max_points > 0 ? std::min(n, static_cast<size_t>(max_points)) : n;
  out->points.reserve(out->points.size() + kept);
  size_t ordinal = 0, next = 0;  // candidate ordinal, index k of the next one kept
  const cv::Mat& image = keyframe.level(level);
  for (int y = 0; y < sums.height && next < kept; ++y) {
    const float* row = image.ptr<float>(y);
    for (int x = 0; x < sums.width && next < kept; ++x) {
      const int i = y * sums.width + x;
      if (!is_candidate(i)) continue;
      if (ordinal++ != next * n / kept) continue;
      ++next;
      ReferencePoint point;
      point.pixel = Eigen::Vector2d(x, y);
      point.idepth = sums.weighted_idepth(i) / sums.weight(i);
      point.idepth_var = sums.count(i) / sums.weight(i);
      point.intensity = row[3 * x];
      point.edge_id = sums.edge_id(i);
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
  const auto camera_at = [&](int level) {
    reference.levels[level].camera = camera.AtLevel(level);
    return &reference.levels[level];
  };
  const MapSums level0(map);
  AddPoints(level0, keyframe, keyframe_lines, 0, max_points_per_level, camera_at(0));
  if (keyframe.num_levels() < 2) return reference;
  LevelSums sums = Aggregate(level0, keyframe.width(1), keyframe.height(1));
  for (int level = 1; level < keyframe.num_levels(); ++level) {
    if (level > 1) sums = Aggregate(sums, keyframe.width(level), keyframe.height(level));
    AddPoints(sums, keyframe, keyframe_lines, level, max_points_per_level, camera_at(level));
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
    if (UpperMedian(d) <= max_median_px) continue;
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
