#include "backend/windowed_ba/point_selection.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace pldvo {

std::vector<int> SelectWindowPoints(const std::vector<WindowedBAPoint>& points,
                                    const ImagePyramid& pyramid, int budget, double min_gradient,
                                    double pattern_radius) {
  std::vector<int> selected;
  if (budget <= 0 || points.empty()) return selected;
  const int width = pyramid.width(0);
  const int height = pyramid.height(0);
  const double cell = std::max(1.0, std::sqrt(static_cast<double>(width) * height / budget));
  const int cells_x = static_cast<int>(std::ceil(width / cell));
  const int cells_y = static_cast<int>(std::ceil(height / cell));
  // Per cell: (gradient, index) of the best candidate so far; index -1 when empty.
  std::vector<std::pair<double, int>> best(static_cast<size_t>(cells_x) * cells_y, {0.0, -1});
  const double lo = 1.0 + pattern_radius;
  const double hi_x = width - 2.0 - pattern_radius;
  const double hi_y = height - 2.0 - pattern_radius;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const Eigen::Vector2d& pixel = points[i].pixel;
    if (!(pixel.x() >= lo && pixel.y() >= lo && pixel.x() < hi_x && pixel.y() < hi_y)) continue;
    const Eigen::Vector3f sample = pyramid.Sample(0, pixel.x(), pixel.y());
    const double gradient = std::hypot(sample[1], sample[2]);
    if (!(gradient >= min_gradient)) continue;
    const int cx = std::min(cells_x - 1, static_cast<int>(pixel.x() / cell));
    const int cy = std::min(cells_y - 1, static_cast<int>(pixel.y() / cell));
    std::pair<double, int>& entry = best[static_cast<size_t>(cy) * cells_x + cx];
    if (entry.second < 0 || gradient > entry.first) entry = {gradient, i};
  }
  std::vector<std::pair<double, int>> winners;
  for (const auto& entry : best) {
    if (entry.second >= 0) winners.push_back(entry);
  }
  std::sort(winners.begin(), winners.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  if (static_cast<int>(winners.size()) > budget) winners.resize(budget);
  selected.reserve(winners.size());
  for (const auto& winner : winners) selected.push_back(winner.second);
  return selected;
}

}  // namespace pldvo
