#include "backend/mapping/depth_regularizer.h"

#include <algorithm>
#include <vector>

namespace pldvo {

int SmoothDepthMap(const SemiDenseDepthMap& in, const MappingOptions& options,
                   SemiDenseDepthMap* out) {
  *out = in;
  const int r = options.regularization_radius;
  const double gate_sq = options.regularization_gate_sigmas * options.regularization_gate_sigmas;
  int smoothed = 0;
  for (int y = 0; y < in.height(); ++y) {
    for (int x = 0; x < in.width(); ++x) {
      const int i = in.Index(x, y);
      if (!in.valid(i)) continue;
      const double d_i = in.idepth(i), v_i = in.idepth_var(i);
      double sum = d_i / v_i, sum_info = 1.0 / v_i;
      int neighbours = 0;
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= in.height()) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if ((dx == 0 && dy == 0) || xx < 0 || xx >= in.width()) continue;
          const int j = in.Index(xx, yy);
          if (!in.valid(j)) continue;
          const double d_j = in.idepth(j), v_j = in.idepth_var(j);
          if ((d_i - d_j) * (d_i - d_j) > gate_sq * (v_i + v_j)) continue;
          sum += d_j / v_j;
          sum_info += 1.0 / v_j;
          ++neighbours;
        }
      }
      if (neighbours > 0) {
        out->SetIdepth(i, sum / sum_info);
        ++smoothed;
      }
    }
  }
  return smoothed;
}

int RemoveIsolatedHypotheses(const MappingOptions& options, SemiDenseDepthMap* map) {
  const int r = options.regularization_radius;
  const double gate_sq = options.regularization_gate_sigmas * options.regularization_gate_sigmas;
  std::vector<int> removed;
  for (int y = 0; y < map->height(); ++y) {
    for (int x = 0; x < map->width(); ++x) {
      const int i = map->Index(x, y);
      if (!map->valid(i)) continue;
      const double d_i = map->idepth(i), v_i = map->idepth_var(i);
      int neighbours = 0;
      for (int dy = -r; dy <= r && neighbours < options.min_neighbors_keep; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= map->height()) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if ((dx == 0 && dy == 0) || xx < 0 || xx >= map->width()) continue;
          const int j = map->Index(xx, yy);
          if (!map->valid(j)) continue;
          const double d_j = map->idepth(j);
          if ((d_i - d_j) * (d_i - d_j) <= gate_sq * (v_i + map->idepth_var(j))) ++neighbours;
        }
      }
      if (neighbours < options.min_neighbors_keep) removed.push_back(i);
    }
  }
  for (int i : removed) map->Invalidate(i);
  return static_cast<int>(removed.size());
}

int FillHoles(const MappingOptions& options, SemiDenseDepthMap* map) {
  const int r = options.regularization_radius;
  std::vector<std::pair<int, double>> filled;
  for (int y = 0; y < map->height(); ++y) {
    for (int x = 0; x < map->width(); ++x) {
      const int i = map->Index(x, y);
      if (map->valid(i) || !map->candidate(i) || map->blacklist(i) >= options.blacklist_threshold) {
        continue;
      }
      double sum = 0.0, sum_info = 0.0;
      int neighbours = 0;
      for (int dy = -r; dy <= r; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= map->height()) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= map->width()) continue;
          const int j = map->Index(xx, yy);
          if (!map->valid(j)) continue;
          sum += map->idepth(j) / map->idepth_var(j);
          sum_info += 1.0 / map->idepth_var(j);
          ++neighbours;
        }
      }
      if (neighbours >= options.min_neighbors_fill) filled.emplace_back(i, sum / sum_info);
    }
  }
  for (const auto& [i, idepth] : filled) {
    map->Set(i, idepth, options.init_idepth_var, options.validity_initial);
  }
  return static_cast<int>(filled.size());
}

}  // namespace pldvo
