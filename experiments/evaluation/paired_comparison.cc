#include "experiments/evaluation/paired_comparison.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <stdexcept>

#include "core/statistics.h"

namespace pldvo {
namespace {

struct Side {
  std::vector<double> values;
  int failed = 0;
};

std::map<std::string, Side> BySequence(const std::vector<RunFigure>& runs, const char* name) {
  std::map<std::string, Side> sides;
  for (const RunFigure& run : runs) {
    Side& side = sides[run.sequence];
    if (!run.evaluated) {
      ++side.failed;
      continue;
    }
    if (!(run.value > 0.0) || !std::isfinite(run.value)) {
      throw std::invalid_argument(std::string("paired comparison: the ") + name + " run of '" +
                                  run.sequence + "' has a figure that is not positive and finite");
    }
    side.values.push_back(run.value);
  }
  return sides;
}

}  // namespace

double TwoSidedSignTestP(int k, int n) {
  if (n <= 0) return 1.0;
  if (k < 0 || k > n) throw std::invalid_argument("sign test: k must be in [0, n]");
  // Sum the binomial(n, 1/2) probabilities of the outcomes at least as far from n/2 as k, in
  // logs (n may be in the hundreds).
  const double distance = std::abs(k - 0.5 * n);
  double p = 0.0;
  for (int i = 0; i <= n; ++i) {
    if (std::abs(i - 0.5 * n) + 1e-9 < distance) continue;
    p += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) -
                  n * std::log(2.0));
  }
  return std::min(1.0, p);
}

PairedComparison ComparePaired(const std::vector<RunFigure>& baseline,
                               const std::vector<RunFigure>& candidate,
                               const PairedComparisonOptions& options) {
  if (!(options.margin >= 0.0) || !(options.margin < 1.0)) {
    throw std::invalid_argument("paired comparison: margin must be in [0, 1)");
  }
  if (options.bootstrap_samples < 100) {
    throw std::invalid_argument("paired comparison: bootstrap_samples must be >= 100");
  }
  if (!(options.confidence > 0.0) || !(options.confidence < 1.0)) {
    throw std::invalid_argument("paired comparison: confidence must be in (0, 1)");
  }
  const std::map<std::string, Side> base = BySequence(baseline, "baseline");
  const std::map<std::string, Side> cand = BySequence(candidate, "candidate");

  PairedComparison result;
  for (const auto& [sequence, side] : base) result.baseline_failed += side.failed;
  for (const auto& [sequence, side] : cand) result.candidate_failed += side.failed;
  std::vector<std::string> sequences;
  for (const auto& entry : base) sequences.push_back(entry.first);
  for (const auto& entry : cand) {
    if (base.count(entry.first) == 0) sequences.push_back(entry.first);
  }
  std::sort(sequences.begin(), sequences.end());
  std::vector<double> logs;
  for (const std::string& sequence : sequences) {
    const auto b = base.find(sequence);
    const auto c = cand.find(sequence);
    if (b == base.end() || c == cand.end() || b->second.values.empty() ||
        c->second.values.empty()) {
      result.unpaired.push_back(sequence);
      continue;
    }
    PairedRow row;
    row.sequence = sequence;
    row.baseline = Median(b->second.values);
    row.candidate = Median(c->second.values);
    row.ratio = row.candidate / row.baseline;
    row.baseline_runs = static_cast<int>(b->second.values.size());
    row.candidate_runs = static_cast<int>(c->second.values.size());
    row.baseline_failed = b->second.failed;
    row.candidate_failed = c->second.failed;
    result.rows.push_back(row);
    logs.push_back(std::log(row.ratio));
    if (row.ratio < 1.0 - options.margin) ++result.better;
    if (row.ratio > 1.0 + options.margin) ++result.worse;
    if (row.ratio < 1.0) ++result.lower;
    if (row.ratio > 1.0) ++result.higher;
  }
  if (logs.empty()) return result;

  const double mean_log = Mean(logs);
  result.geometric_mean_ratio = std::exp(mean_log);
  if (logs.size() > 1) {
    double sum_squares = 0.0;
    for (double v : logs) sum_squares += (v - mean_log) * (v - mean_log);
    result.log_ratio_sd = std::sqrt(sum_squares / static_cast<double>(logs.size() - 1));
  }
  result.sign_test_p = TwoSidedSignTestP(result.lower, result.lower + result.higher);

  // Percentile bootstrap of the mean log ratio over the rows.
  std::mt19937 random(options.seed);
  std::uniform_int_distribution<size_t> pick(0, logs.size() - 1);
  std::vector<double> means(static_cast<size_t>(options.bootstrap_samples));
  for (double& mean : means) {
    double sum = 0.0;
    for (size_t i = 0; i < logs.size(); ++i) sum += logs[pick(random)];
    mean = sum / static_cast<double>(logs.size());
  }
  std::sort(means.begin(), means.end());
  const double tail = 0.5 * (1.0 - options.confidence);
  const auto at = [&](double quantile) {
    const double position = quantile * static_cast<double>(means.size() - 1);
    const size_t below = static_cast<size_t>(std::floor(position));
    const size_t above = std::min(below + 1, means.size() - 1);
    const double weight = position - static_cast<double>(below);
    return (1.0 - weight) * means[below] + weight * means[above];
  };
  result.interval_low = std::exp(at(tail));
  result.interval_high = std::exp(at(1.0 - tail));
  return result;
}

}  // namespace pldvo
