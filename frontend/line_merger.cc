#include "frontend/line_merger.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace pldvo {
namespace {

// Directed angle in [0, 2 pi) to its bin.
int AngleBin(double angle, int num_bins) {
  double a = std::fmod(angle, 2.0 * M_PI);
  if (a < 0.0) a += 2.0 * M_PI;
  return std::min(num_bins - 1, static_cast<int>(a / (2.0 * M_PI) * num_bins));
}

// The segment being grown: weighted sums of its parts and all their endpoints.
struct Cluster {
  Eigen::Vector2d weighted_direction = Eigen::Vector2d::Zero();
  Eigen::Vector2d weighted_midpoint = Eigen::Vector2d::Zero();
  double weight = 0.0;
  int octave = 0;
  std::vector<Eigen::Vector2d> endpoints;
  // Current fitted segment.
  Eigen::Vector2d origin, direction;
  double lo = 0.0, hi = 0.0;

  void Add(const LineSegment& s) {
    const double w = s.length / std::ldexp(1.0, 2 * s.octave);
    weighted_direction += w * s.direction();
    weighted_midpoint += w * s.midpoint();
    weight += w;
    octave = endpoints.empty() ? s.octave : std::min(octave, s.octave);
    endpoints.push_back(s.start);
    endpoints.push_back(s.end);
    direction = weighted_direction.normalized();
    origin = weighted_midpoint / weight;
    lo = hi = direction.dot(endpoints[0] - origin);
    for (const Eigen::Vector2d& p : endpoints) {
      const double t = direction.dot(p - origin);
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
  }
  double length() const { return hi - lo; }
  Eigen::Vector2d Start() const { return origin + lo * direction; }
  Eigen::Vector2d End() const { return origin + hi * direction; }
};

// `segments` sorted longest first: keeps the first max_segments (0 = all).
void KeepLongest(int max_segments, std::vector<LineSegment>* segments) {
  if (max_segments > 0 && segments->size() > static_cast<size_t>(max_segments)) {
    segments->resize(max_segments);
  }
}

}  // namespace

LineMerger::LineMerger(const LineMergerOptions& options, double endpoint_sigma_px)
    : options_(options), endpoint_sigma_px_(endpoint_sigma_px) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument("LineMergerOptions: " + error);
}

std::vector<LineSegment> LineMerger::Merge(const std::vector<LineSegment>& segments) const {
  std::vector<LineSegment> merged;
  if (!options_.enabled) {
    for (const LineSegment& s : segments) {
      if (s.length >= options_.min_length_px) merged.push_back(s);
    }
    std::sort(merged.begin(), merged.end(),
              [](const LineSegment& a, const LineSegment& b) { return a.length > b.length; });
    KeepLongest(options_.max_segments, &merged);
    return merged;
  }
  if (segments.empty()) return merged;

  // Bucket grid over the midpoints' bounding box.
  const double cell = options_.cell_size_px;
  const int num_bins = options_.num_angle_bins;
  Eigen::Vector2d lo = segments[0].midpoint(), hi = lo;
  for (const LineSegment& s : segments) {
    lo = lo.cwiseMin(s.midpoint());
    hi = hi.cwiseMax(s.midpoint());
  }
  const int cells_x = static_cast<int>((hi.x() - lo.x()) / cell) + 1;
  const int cells_y = static_cast<int>((hi.y() - lo.y()) / cell) + 1;
  std::vector<std::vector<int>> buckets(static_cast<size_t>(cells_x) * cells_y * num_bins);
  auto cell_of = [&](const Eigen::Vector2d& p, int* cx, int* cy) {
    *cx = static_cast<int>(std::floor((p.x() - lo.x()) / cell));
    *cy = static_cast<int>(std::floor((p.y() - lo.y()) / cell));
  };
  for (int i = 0; i < static_cast<int>(segments.size()); ++i) {
    int cx, cy;
    cell_of(segments[i].midpoint(), &cx, &cy);
    buckets[(static_cast<size_t>(cy) * cells_x + cx) * num_bins +
            AngleBin(segments[i].angle, num_bins)]
        .push_back(i);
  }

  std::vector<int> order(segments.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return segments[a].length > segments[b].length; });

  const double max_angle = options_.max_angle_deg * M_PI / 180.0;
  const int bin_reach = static_cast<int>(std::ceil(max_angle / (2.0 * M_PI / num_bins)));
  std::vector<char> consumed(segments.size(), 0);
  std::vector<int> visited_cell(static_cast<size_t>(cells_x) * cells_y, -1);
  std::vector<int> candidates;
  std::vector<int> bins;
  int query = 0;

  for (int seed : order) {
    if (consumed[seed]) continue;
    consumed[seed] = 1;
    Cluster cluster;
    cluster.Add(segments[seed]);
    // Every unmerged segment is at most as long as the seed, so a mergeable segment's midpoint
    // lies within reach = max_gap + seed length / 2 beyond the cluster's ends and within the
    // distance threshold of its line; walk the cells along that stretch.
    const double reach = options_.max_gap_px + 0.5 * segments[seed].length;
    for (bool grew = true; grew;) {
      grew = false;
      ++query;
      candidates.clear();
      const double t0 = cluster.lo - reach, t1 = cluster.hi + reach;
      const int steps = static_cast<int>((t1 - t0) / (0.5 * cell)) + 1;
      const int seed_bin =
          AngleBin(std::atan2(cluster.direction.y(), cluster.direction.x()), num_bins);
      bins.clear();
      for (int db = -bin_reach; db <= bin_reach && db - (-bin_reach) < num_bins; ++db) {
        bins.push_back(((seed_bin + db) % num_bins + num_bins) % num_bins);
      }
      for (int k = 0; k <= steps; ++k) {
        const Eigen::Vector2d p = cluster.origin + (t0 + (t1 - t0) * k / steps) * cluster.direction;
        int pcx, pcy;
        cell_of(p, &pcx, &pcy);
        for (int cy = pcy - 1; cy <= pcy + 1; ++cy) {
          for (int cx = pcx - 1; cx <= pcx + 1; ++cx) {
            if (cx < 0 || cy < 0 || cx >= cells_x || cy >= cells_y) continue;
            const size_t cell_index = static_cast<size_t>(cy) * cells_x + cx;
            if (visited_cell[cell_index] == query) continue;
            visited_cell[cell_index] = query;
            for (int bin : bins) {
              for (int j : buckets[cell_index * num_bins + bin]) {
                if (!consumed[j]) candidates.push_back(j);
              }
            }
          }
        }
      }
      const double seed_angle = std::atan2(cluster.direction.y(), cluster.direction.x());
      for (int j : candidates) {
        if (consumed[j]) continue;
        const LineSegment& s = segments[j];
        if (AngleDifference(s.angle, seed_angle) > max_angle) continue;
        const Eigen::Vector2d normal(-cluster.direction.y(), cluster.direction.x());
        if (std::abs(normal.dot(s.start - cluster.origin)) > options_.max_line_distance_px ||
            std::abs(normal.dot(s.end - cluster.origin)) > options_.max_line_distance_px) {
          continue;
        }
        const double a = cluster.direction.dot(s.start - cluster.origin);
        const double b = cluster.direction.dot(s.end - cluster.origin);
        const double gap =
            std::max({0.0, std::min(a, b) - cluster.hi, cluster.lo - std::max(a, b)});
        if (gap > options_.max_gap_px) continue;
        cluster.Add(s);
        consumed[j] = 1;
        grew = true;
      }
    }
    if (cluster.length() >= options_.min_length_px) {
      merged.push_back(MakeLineSegment(cluster.Start(), cluster.End(), cluster.octave,
                                       endpoint_sigma_px_ * std::ldexp(1.0, cluster.octave)));
    }
  }
  std::stable_sort(merged.begin(), merged.end(),
                   [](const LineSegment& a, const LineSegment& b) { return a.length > b.length; });
  KeepLongest(options_.max_segments, &merged);
  return merged;
}

}  // namespace pldvo
