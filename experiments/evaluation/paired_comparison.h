// A candidate configuration against a baseline over the same sequences, with the uncertainty of
// the verdict (`pldvo compare`, docs/benchmark.md "Comparing two configurations").
//
// Per sequence the figure of each side is the median of its evaluated runs (the initial maps;
// failed runs are counted, not used, as in the ablation tables), and the row's ratio is
// candidate / baseline. Over the rows:
//   - the geometric mean of the ratios, exp(mean(log ratio)): a 2x gain and a 2x loss cancel;
//   - its percentile bootstrap interval (rows drawn with replacement, a fixed seed): the
//     sequences are the independent units, so the interval says how far the mean would move on
//     another set of sequences like these;
//   - the standard deviation of the log ratios: the scatter a placebo change already shows;
//   - rows better / worse by more than `margin` (the 10%), and the exact two-sided sign
//     test on the rows' signs (ties left out).
#ifndef PLDVO_EXPERIMENTS_EVALUATION_PAIRED_COMPARISON_H_
#define PLDVO_EXPERIMENTS_EVALUATION_PAIRED_COMPARISON_H_

#include <cstdint>
#include <string>
#include <vector>

namespace pldvo {

// One run of one sequence: its figure (e.g. RPE cm/s) when it was evaluated.
struct RunFigure {
  std::string sequence;
  bool evaluated = false;  // false: the run failed or has no figure
  double value = 0.0;      // > 0 when evaluated
};

struct PairedComparisonOptions {
  double margin = 0.10;           // "better / worse by more than": ratio < 1 - m or > 1 + m
  int bootstrap_samples = 10000;  // >= 100
  double confidence = 0.95;       // of the bootstrap interval, in (0, 1)
  std::uint32_t seed = 1;         // of the bootstrap's draws
};

struct PairedRow {
  std::string sequence;
  double baseline = 0.0;  // median over the evaluated runs
  double candidate = 0.0;
  double ratio = 0.0;     // candidate / baseline
  int baseline_runs = 0;  // evaluated runs
  int candidate_runs = 0;
  int baseline_failed = 0;  // runs without a figure
  int candidate_failed = 0;
};

struct PairedComparison {
  std::vector<PairedRow> rows;        // sequences with an evaluated run on both sides, sorted
  std::vector<std::string> unpaired;  // sequences that lack one on a side, sorted
  double geometric_mean_ratio = 1.0;  // 1 without rows
  double interval_low = 1.0;          // bootstrap interval of the geometric mean
  double interval_high = 1.0;
  double log_ratio_sd = 0.0;  // sample standard deviation (n - 1); 0 below 2 rows
  int better = 0;             // ratio < 1 - margin
  int worse = 0;              // ratio > 1 + margin
  int lower = 0;              // ratio < 1 (the sign test's counts)
  int higher = 0;             // ratio > 1
  double sign_test_p = 1.0;   // exact two-sided binomial(lower + higher, 1/2)
  int baseline_failed = 0;    // failed runs over all sequences
  int candidate_failed = 0;
};

// Throws std::invalid_argument for invalid options or an evaluated run whose value is not
// positive and finite.
PairedComparison ComparePaired(const std::vector<RunFigure>& baseline,
                               const std::vector<RunFigure>& candidate,
                               const PairedComparisonOptions& options = {});

// P(|X - n/2| >= |k - n/2|) for X ~ Binomial(n, 1/2): the exact two-sided sign test of k
// successes in n; 1 for n = 0.
double TwoSidedSignTestP(int k, int n);

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_PAIRED_COMPARISON_H_
