#include "backend/mapping/depth_regularizer.h"

#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

#include "backend/mapping/pixel_stripes.h"

namespace pldvo {
namespace {

// A valid hypothesis with the terms of its inverse-variance weighted mean, info = 1 / V and
// weighted = D / V, computed once with the expressions of the window sum: the sums see the same
// operands in the same order, hence bit-identical results.
struct Hypothesis {
  int x;
  float idepth, idepth_var;
  double info, weighted;
};

// The valid hypotheses of a map in compressed sparse rows (row by row, in increasing x), so that
// a window visits only the valid ones, in the row-major order of the (2r+1)^2 scan.
class ValidRows {
 public:
  explicit ValidRows(const SemiDenseDepthMap& map) {
    hypotheses_.reserve(map.CountValid());
    row_begin_.reserve(map.height() + 1);
    for (int y = 0; y < map.height(); ++y) {
      row_begin_.push_back(static_cast<int>(hypotheses_.size()));
      for (int x = 0, i = map.Index(0, y); x < map.width(); ++x, ++i) {
        if (!map.valid(i)) continue;
        const float d = map.idepth(i), v = map.idepth_var(i);
        hypotheses_.push_back({x, d, v, 1.0 / v, static_cast<double>(d) / v});
      }
    }
    row_begin_.push_back(static_cast<int>(hypotheses_.size()));
  }

  const Hypothesis* begin(int y) const { return hypotheses_.data() + row_begin_[y]; }
  const Hypothesis* end(int y) const { return hypotheses_.data() + row_begin_[y + 1]; }

 private:
  std::vector<Hypothesis> hypotheses_;
  std::vector<int> row_begin_;  // height + 1 offsets into hypotheses_
};

}  // namespace

int SmoothDepthMap(const SemiDenseDepthMap& in, const MappingOptions& options,
                   SemiDenseDepthMap* out) {
  *out = in;
  const int r = options.regularization_radius;
  const double gate_sq = options.regularization_gate_sigmas * options.regularization_gate_sigmas;
  const ValidRows rows(in);
  // In stripes of rows (pixel_stripes.h): each writes only its own pixels.
  const int stripes = NumStripes(options);
  std::vector<int> smoothed(stripes, 0);
  ForEachStripe(stripes, [&](int stripe) {
    // Per window row, the first hypothesis not left of the window of the current pixel: the
    // pixels of a row come in increasing x, so the cursors only move forward.
    std::vector<const Hypothesis*> first(2 * r + 1);
    const int y_end = in.height() * (stripe + 1) / stripes;
    for (int y = in.height() * stripe / stripes; y < y_end; ++y) {
      const int y0 = std::max(y - r, 0), y1 = std::min(y + r, in.height() - 1);
      for (int yy = y0; yy <= y1; ++yy) first[yy - y0] = rows.begin(yy);
      for (const Hypothesis* h_i = rows.begin(y); h_i != rows.end(y); ++h_i) {
        const int x = h_i->x;
        const double d_i = h_i->idepth, v_i = h_i->idepth_var;
        double sum = h_i->weighted, sum_info = h_i->info;
        int neighbours = 0;
        for (int yy = y0; yy <= y1; ++yy) {
          const Hypothesis* const end = rows.end(yy);
          const Hypothesis*& begin = first[yy - y0];
          while (begin != end && begin->x < x - r) ++begin;
          for (const Hypothesis* h_j = begin; h_j != end && h_j->x <= x + r; ++h_j) {
            if (h_j == h_i) continue;
            const double d_j = h_j->idepth, v_j = h_j->idepth_var;
            if ((d_i - d_j) * (d_i - d_j) > gate_sq * (v_i + v_j)) continue;
            sum += h_j->weighted;
            sum_info += h_j->info;
            ++neighbours;
          }
        }
        if (neighbours > 0) {
          out->SetIdepth(in.Index(x, y), sum / sum_info);
          ++smoothed[stripe];
        }
      }
    }
  });
  return std::accumulate(smoothed.begin(), smoothed.end(), 0);
}

int RemoveIsolatedHypotheses(const MappingOptions& options, SemiDenseDepthMap* map) {
  const int r = options.regularization_radius;
  const double gate_sq = options.regularization_gate_sigmas * options.regularization_gate_sigmas;
  // Found in stripes of rows of the unchanged map, removed after.
  const SemiDenseDepthMap& in = *map;
  const std::vector<int> removed = CollectRowsInStripes<int>(
      in.height(), NumStripes(options), [&](int y, std::vector<int>* found) {
        for (int x = 0; x < in.width(); ++x) {
          const int i = in.Index(x, y);
          if (!in.valid(i)) continue;
          const double d_i = in.idepth(i), v_i = in.idepth_var(i);
          int neighbours = 0;
          for (int dy = -r; dy <= r && neighbours < options.min_neighbors_keep; ++dy) {
            const int yy = y + dy;
            if (yy < 0 || yy >= in.height()) continue;
            for (int dx = -r; dx <= r; ++dx) {
              const int xx = x + dx;
              if ((dx == 0 && dy == 0) || xx < 0 || xx >= in.width()) continue;
              const int j = in.Index(xx, yy);
              if (!in.valid(j)) continue;
              const double d_j = in.idepth(j);
              if ((d_i - d_j) * (d_i - d_j) <= gate_sq * (v_i + in.idepth_var(j))) ++neighbours;
            }
          }
          if (neighbours < options.min_neighbors_keep) found->push_back(i);
        }
      });
  for (int i : removed) map->Invalidate(i);
  return static_cast<int>(removed.size());
}

int FillHoles(const MappingOptions& options, SemiDenseDepthMap* map) {
  const int r = options.regularization_radius;
  // Computed in stripes of rows of the unchanged map, filled after.
  const SemiDenseDepthMap& in = *map;
  const std::vector<std::pair<int, double>> filled = CollectRowsInStripes<std::pair<int, double>>(
      in.height(), NumStripes(options), [&](int y, std::vector<std::pair<int, double>>* found) {
        for (int x = 0; x < in.width(); ++x) {
          const int i = in.Index(x, y);
          if (in.valid(i) || !in.candidate(i) || in.blacklist(i) >= options.blacklist_threshold) {
            continue;
          }
          double sum = 0.0, sum_info = 0.0;
          int neighbours = 0;
          for (int dy = -r; dy <= r; ++dy) {
            const int yy = y + dy;
            if (yy < 0 || yy >= in.height()) continue;
            for (int dx = -r; dx <= r; ++dx) {
              const int xx = x + dx;
              if (xx < 0 || xx >= in.width()) continue;
              const int j = in.Index(xx, yy);
              if (!in.valid(j)) continue;
              sum += in.idepth(j) / in.idepth_var(j);
              sum_info += 1.0 / in.idepth_var(j);
              ++neighbours;
            }
          }
          if (neighbours >= options.min_neighbors_fill) found->emplace_back(i, sum / sum_info);
        }
      });
  for (const auto& [i, idepth] : filled) {
    map->Set(i, idepth, options.init_idepth_var, options.validity_initial);
  }
  return static_cast<int>(filled.size());
}

}  // namespace pldvo
