// `pldvo compare --baseline A --candidate B [--baseline_config NAME] [--candidate_config NAME]
//               [--metric rpe_cm_s] [--filter REGEX] [--margin 0.1] [--bootstrap_samples 10000]
//               [--json]`:
// a candidate configuration against a baseline over the sequences both were run on, from the
// results.csv of `pldvo ablate` (A and B: an ablation's OUT folder or its results.csv; the same
// one for two configs of one ablation). Per sequence the median over the initial maps and the
// ratio; over the sequences the geometric mean with its bootstrap interval, the rows better and
// worse by more than the margin and the sign test (experiments/evaluation/paired_comparison.h,
// docs/benchmark.md "Comparing two configurations"). Exit 2 on a usage error (a missing flag, an
// unknown column or config), 1 when a file cannot be read.
#include <gflags/gflags.h>

#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"
#include "experiments/evaluation/paired_comparison.h"

DEFINE_string(baseline, "", "The baseline's ablation folder (pldvo ablate --out) or results.csv.");
DEFINE_string(candidate, "", "The candidate's ablation folder or results.csv.");
DEFINE_string(baseline_config, "",
              "Config name (results.csv column `config`) of the baseline; may be empty when the "
              "file holds one config.");
DEFINE_string(candidate_config, "", "Config name of the candidate; as --baseline_config.");
DEFINE_string(metric, "rpe_cm_s",
              "results.csv column compared (positive figures, lower is better: rpe_cm_s, "
              "rpe_deg_s, ate_m, ms_median_tracking_thread, ...).");
DEFINE_string(filter, "",
              "Only the sequences whose name matches this regular expression (ECMAScript, "
              "searched), e.g. '_s[345]$'; empty: all.");
DEFINE_double(margin, 0.10, "Rows better / worse by more than this fraction are counted.");
DEFINE_int32(bootstrap_samples, 10000, "Draws of the bootstrap interval (>= 100).");
DEFINE_double(confidence, 0.95, "Confidence of the bootstrap interval.");

namespace pldvo {
namespace {

// A usage error: exit 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

// The runs of `config` in results.csv at `where` (a folder or the file): one RunFigure per row.
std::vector<RunFigure> ReadRuns(const std::string& where, const std::string& config,
                                const std::string& metric, const std::regex* filter,
                                std::string* config_used) {
  std::filesystem::path path(where);
  if (std::filesystem::is_directory(path)) path /= "results.csv";
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot read " + path.string());
  std::string line;
  if (!std::getline(file, line)) throw std::runtime_error(path.string() + " is empty");
  const std::vector<std::string> header = SplitCsvLine(line);
  auto column = [&](const std::string& name) {
    for (size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    throw UsageError(path.string() + " has no column '" + name + "'");
  };
  const int dataset_column = column("dataset");
  const int config_column = column("config");
  const int status_column = column("status");
  const int metric_column = column(metric);
  std::vector<std::vector<std::string>> rows;
  std::set<std::string> configs;
  while (std::getline(file, line)) {
    if (line.empty()) continue;
    std::vector<std::string> fields = SplitCsvLine(line);
    fields.resize(header.size());
    configs.insert(fields[config_column]);
    rows.push_back(std::move(fields));
  }
  std::string names;  // for the errors
  for (const std::string& name : configs) names += " " + name;
  std::string chosen = config;
  if (chosen.empty()) {
    if (configs.size() != 1) {
      throw UsageError(path.string() + " holds " + std::to_string(configs.size()) +
                       " configs; choose one with --baseline_config / --candidate_config:" + names);
    }
    chosen = *configs.begin();
  } else if (configs.count(chosen) == 0) {
    throw UsageError(path.string() + " has no config '" + chosen + "'; it has:" + names);
  }
  *config_used = chosen;
  std::vector<RunFigure> runs;
  for (const std::vector<std::string>& fields : rows) {
    if (fields[config_column] != chosen) continue;
    if (filter != nullptr && !std::regex_search(fields[dataset_column], *filter)) continue;
    RunFigure run;
    run.sequence = fields[dataset_column];
    if (fields[status_column] == "ok" && !fields[metric_column].empty()) {
      try {
        run.value = std::stod(fields[metric_column]);
        run.evaluated = std::isfinite(run.value);
      } catch (const std::exception&) {
        throw std::runtime_error(path.string() + ": '" + fields[metric_column] + "' in column " +
                                 metric + " is not a number");
      }
    }
    runs.push_back(run);
  }
  return runs;
}

void PrintText(const PairedComparison& result, const std::string& baseline_name,
               const std::string& candidate_name) {
  std::cout << FLAGS_metric << ": candidate " << candidate_name << " against baseline "
            << baseline_name << " (median over each sequence's evaluated runs)\n\n"
            << "| sequence | baseline | runs | candidate | runs | ratio |\n"
            << "| --- | ---: | ---: | ---: | ---: | ---: |\n";
  std::cout << std::fixed;
  for (const PairedRow& row : result.rows) {
    auto runs = [](int ok, int failed) {
      return std::to_string(ok) + (failed > 0 ? " (+" + std::to_string(failed) + " failed)" : "");
    };
    std::cout << "| " << row.sequence << " | " << std::setprecision(4) << row.baseline << " | "
              << runs(row.baseline_runs, row.baseline_failed) << " | " << row.candidate << " | "
              << runs(row.candidate_runs, row.candidate_failed) << " | " << std::setprecision(3)
              << row.ratio << " |\n";
  }
  const int n = static_cast<int>(result.rows.size());
  std::cout << "\nsequences compared: " << n;
  if (!result.unpaired.empty()) {
    std::cout << "; left out (no evaluated run on one side):";
    for (const std::string& name : result.unpaired) std::cout << " " << name;
  }
  std::cout << "\ngeometric mean of the ratios " << std::setprecision(3)
            << result.geometric_mean_ratio << ", " << std::setprecision(0)
            << 100.0 * FLAGS_confidence << "% bootstrap interval [" << std::setprecision(3)
            << result.interval_low << ", " << result.interval_high << "] ("
            << FLAGS_bootstrap_samples << " draws of the sequences)\n"
            << "standard deviation of the log ratios " << result.log_ratio_sd << "\n"
            << "better by more than " << std::setprecision(0) << 100.0 * FLAGS_margin
            << "%: " << result.better << " of " << n << ", worse: " << result.worse << "\n"
            << "sign test: " << result.lower << " lower, " << result.higher
            << " higher, two-sided p = " << std::defaultfloat << std::setprecision(2)
            << result.sign_test_p << std::fixed << "\n"
            << "failed runs: baseline " << result.baseline_failed << ", candidate "
            << result.candidate_failed << "\n";
}

void PrintJson(const PairedComparison& result, const std::string& baseline_name,
               const std::string& candidate_name) {
  nlohmann::json json;
  json["metric"] = FLAGS_metric;
  json["baseline"] = baseline_name;
  json["candidate"] = candidate_name;
  json["rows"] = nlohmann::json::array();
  for (const PairedRow& row : result.rows) {
    json["rows"].push_back({{"sequence", row.sequence},
                            {"baseline", row.baseline},
                            {"candidate", row.candidate},
                            {"ratio", row.ratio},
                            {"baseline_runs", row.baseline_runs},
                            {"candidate_runs", row.candidate_runs},
                            {"baseline_failed", row.baseline_failed},
                            {"candidate_failed", row.candidate_failed}});
  }
  json["unpaired"] = result.unpaired;
  json["geometric_mean_ratio"] = result.geometric_mean_ratio;
  json["interval"] = {result.interval_low, result.interval_high};
  json["confidence"] = FLAGS_confidence;
  json["log_ratio_sd"] = result.log_ratio_sd;
  json["better"] = result.better;
  json["worse"] = result.worse;
  json["margin"] = FLAGS_margin;
  json["lower"] = result.lower;
  json["higher"] = result.higher;
  json["sign_test_p"] = result.sign_test_p;
  json["baseline_failed"] = result.baseline_failed;
  json["candidate_failed"] = result.candidate_failed;
  std::cout << json.dump(2) << "\n";
}

int RunCompare(const CommandContext& context) {
  if (!context.config_overrides.empty()) {
    std::cerr << "pldvo compare: takes no --set\n";
    return 2;
  }
  if (FLAGS_baseline.empty() || FLAGS_candidate.empty()) {
    std::cerr << "pldvo compare: --baseline and --candidate are required\n";
    return 2;
  }
  try {
    PairedComparisonOptions options;
    options.margin = FLAGS_margin;
    options.bootstrap_samples = FLAGS_bootstrap_samples;
    options.confidence = FLAGS_confidence;
    std::regex filter;
    try {
      filter = std::regex(FLAGS_filter, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      throw UsageError("--filter '" + FLAGS_filter + "' is not a regular expression: " + e.what());
    }
    const std::regex* filter_or_all = FLAGS_filter.empty() ? nullptr : &filter;
    std::string baseline_config, candidate_config;
    const std::vector<RunFigure> baseline = ReadRuns(FLAGS_baseline, FLAGS_baseline_config,
                                                     FLAGS_metric, filter_or_all, &baseline_config);
    const std::vector<RunFigure> candidate = ReadRuns(
        FLAGS_candidate, FLAGS_candidate_config, FLAGS_metric, filter_or_all, &candidate_config);
    PairedComparison result;
    try {
      result = ComparePaired(baseline, candidate, options);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    const std::string baseline_name = baseline_config + " of " + FLAGS_baseline;
    const std::string candidate_name = candidate_config + " of " + FLAGS_candidate;
    if (FLAGS_json) {
      PrintJson(result, baseline_name, candidate_name);
    } else {
      PrintText(result, baseline_name, candidate_name);
    }
    return 0;
  } catch (const UsageError& e) {
    std::cerr << "pldvo compare: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "pldvo compare: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

PLDVO_REGISTER_COMMAND("compare",
                       "A candidate config against a baseline over ablation results: per-sequence "
                       "ratios, geometric mean with a bootstrap interval, sign test.",
                       RunCompare, "json");

}  // namespace pldvo
