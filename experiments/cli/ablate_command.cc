// `pldvo ablate --configs A.yaml,B.yaml --datasets DIR1,DIR2 --out OUT [--jobs N] [--shard i/N]
//              [--repeats R] [--run_max_frames N] [--set key=value]...`: `pldvo run` for every
// (dataset, config) pair, each in its own subprocess of this binary (a crash or hang of one run
// cannot take the others down), N at a time. With --repeats R every pair runs R times, repeat k
// with mapping.init_seed = k (the monocular random initial map; docs/odometry.md). Run k (dataset,
// config, repeat order) belongs to shard k mod N. Per run: OUT/runs/<dataset>__<config>/ (with
// R > 1: .../<dataset>__<config>__seed<k>/) holds the run's outputs and log.txt. Then, over the
// whole grid (runs of other shards count when their summary.json exists in OUT):
//   OUT/results.csv                  one row per run (status, counts, RPE, ATE, timing, scale
//                                    segments; new columns are appended, scripts/targets.sh
//                                    reads them by position);
//   OUT/results.md                   RPE tables like the paper's Tables I/II (X: failed run;
//                                    with R > 1 the median and [min, max] over the repeats);
//   OUT/trajectories_<dataset>.svg   top view, Sim(3)-aligned estimates (repeat 1) against
//                                    ground truth.
//   OUT/results.json                 per (dataset, config) cell: runs, ok / failed / not-run
//                                    counts, lost events and the median, min and max of RPE,
//                                    ATE, scale drift and tracking-thread time over the repeats.
// --set overrides are passed to every run. Exit status 0 when every run of this shard succeeded.
// --collect runs nothing: it writes the tables from the runs found in OUT, as the last shard
// would (a separate step after the shards of a cluster job array, experiments/cluster/
// ablate.sbatch, docs/cluster.md); it needs the same --configs, --datasets and --repeats, and
// exits 1 when some run of the grid has no summary.
#include <fcntl.h>
#include <gflags/gflags.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/dataset.h"
#include "core/evaluation.h"
#include "core/statistics.h"
#include "core/trajectory_io.h"
#include "core/trajectory_svg.h"
#include "experiments/cli/command.h"
#include "experiments/cli/common_flags.h"

extern char** environ;

DEFINE_string(configs, "", "Comma-separated config YAML files (one column each).");
DEFINE_string(datasets, "", "Comma-separated dataset folders (one row each).");
DEFINE_int32(jobs, 1, "Runs in parallel (each a subprocess).");
DEFINE_string(shard, "0/1", "i/N: run only the pairs k with k mod N == i.");
DEFINE_bool(skip_existing, false, "Do not rerun pairs whose summary.json exists.");
DEFINE_int32(run_max_frames, 0,
             "Passed to every run as --max_frames: only the first N frames (0 = all).");
DEFINE_int32(repeats, 1,
             "Runs per pair; repeat k sets mapping.init_seed=k. Tables: median [min, max].");
DEFINE_bool(collect, false,
            "Run nothing: write results.csv/.md/.json from the runs found in --out (after the "
            "shards of a job array).");

namespace pldvo {
namespace {

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

std::string Stem(const std::string& path) {
  std::filesystem::path p(path);
  while (!p.empty() && p.filename().empty()) p = p.parent_path();  // trailing slash
  return p.stem().string();
}

// Unique names: the stems, with _2, _3, ... appended to repeats.
std::vector<std::string> UniqueNames(const std::vector<std::string>& paths) {
  std::vector<std::string> names;
  for (const std::string& path : paths) {
    std::string name = Stem(path);
    const std::string base = name;
    for (int k = 2; std::find(names.begin(), names.end(), name) != names.end(); ++k) {
      name = base + "_" + std::to_string(k);
    }
    names.push_back(name);
  }
  return names;
}

struct Pair {
  int index = 0;
  int dataset = 0;
  int config = 0;
  int repeat = 1;  // 1..repeats; with repeats > 1 also the run's mapping.init_seed
  std::string dir;
  bool ran = false;
  int exit_code = -1;  // of this invocation's run; -1 when not run here
};

std::string SelfExecutable() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string("pldvo") : self.string();
}

// Runs argv with stdout and stderr written to log_path; returns the exit code (128 + signal
// when killed, -1 when it could not start, with the reason in log_path).
int RunProcess(const std::vector<std::string>& args, const std::string& log_path) {
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int spawn_error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error != 0) {
    std::ofstream(log_path, std::ios::app)
        << "pldvo ablate: cannot start " << args[0] << ": " << std::strerror(spawn_error) << "\n";
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      std::ofstream(log_path, std::ios::app)
          << "pldvo ablate: lost the run's process: " << std::strerror(errno) << "\n";
      return -1;
    }
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

nlohmann::json ReadSummary(const std::string& dir) {
  std::ifstream file(dir + "/summary.json");
  if (!file) return nullptr;
  try {
    return nlohmann::json::parse(file);
  } catch (const std::exception&) {
    return nullptr;
  }
}

double JsonNumber(const nlohmann::json& json, const char* key) {
  if (json.is_object() && json.contains(key) && json[key].is_number()) {
    return json[key].get<double>();
  }
  return std::nan("");
}

std::string Fixed(double value, int precision) {
  if (!std::isfinite(value)) return "";
  std::ostringstream out;
  out << std::fixed << std::setprecision(precision) << value;
  return out.str();
}

int RunAblate(const CommandContext& context) {
  const std::vector<std::string> configs = SplitList(FLAGS_configs);
  const std::vector<std::string> datasets = SplitList(FLAGS_datasets);
  if (configs.empty() || datasets.empty() || FLAGS_out.empty()) {
    std::cerr << "pldvo ablate: --configs, --datasets and --out are required\n";
    return 2;
  }
  int shard = 0, num_shards = 1;
  {
    char slash = 0;
    std::istringstream shard_stream(FLAGS_shard);
    if (!(shard_stream >> shard >> slash >> num_shards) || slash != '/' || num_shards < 1 ||
        shard < 0 || shard >= num_shards) {
      std::cerr << "pldvo ablate: --shard must be i/N with 0 <= i < N, got '" << FLAGS_shard
                << "'\n";
      return 2;
    }
  }
  if (FLAGS_repeats < 1) {
    std::cerr << "pldvo ablate: --repeats must be >= 1, got " << FLAGS_repeats << "\n";
    return 2;
  }
  for (const std::string& config : configs) {
    if (!std::filesystem::exists(config)) {
      std::cerr << "pldvo ablate: config file " << config << " does not exist\n";
      return 2;
    }
  }
  const std::string out = FLAGS_out;
  std::filesystem::create_directories(out + "/runs");
  const std::vector<std::string> config_names = UniqueNames(configs);
  const std::vector<std::string> dataset_names = UniqueNames(datasets);

  std::vector<Pair> pairs;
  const int repeats = FLAGS_repeats;
  for (size_t d = 0; d < datasets.size(); ++d) {
    for (size_t c = 0; c < configs.size(); ++c) {
      for (int r = 1; r <= repeats; ++r) {
        Pair pair;
        pair.index = static_cast<int>(pairs.size());
        pair.dataset = static_cast<int>(d);
        pair.config = static_cast<int>(c);
        pair.repeat = r;
        pair.dir = out + "/runs/" + dataset_names[d] + "__" + config_names[c];
        if (repeats > 1) pair.dir += "__seed" + std::to_string(r);
        pairs.push_back(pair);
      }
    }
  }
  std::vector<Pair*> mine;
  for (Pair& pair : pairs) {
    if (FLAGS_collect) break;
    if (pair.index % num_shards != shard) continue;
    if (FLAGS_skip_existing && ReadSummary(pair.dir).is_object()) continue;
    mine.push_back(&pair);
  }

  const std::string self = SelfExecutable();
  std::atomic<size_t> next{0};
  std::mutex print_mutex;
  auto worker = [&]() {
    for (size_t k = next++; k < mine.size(); k = next++) {
      Pair& pair = *mine[k];
      std::filesystem::create_directories(pair.dir);
      std::filesystem::remove(pair.dir + "/summary.json");
      std::vector<std::string> args = {self,
                                       "run",
                                       "--dataset",
                                       datasets[pair.dataset],
                                       "--config",
                                       configs[pair.config],
                                       "--out",
                                       pair.dir,
                                       "--progress=false"};
      if (!FLAGS_camera.empty()) args.insert(args.end(), {"--camera", FLAGS_camera});
      if (!gflags::GetCommandLineFlagInfoOrDie("format").is_default) {
        args.insert(args.end(), {"--format", FLAGS_format});
      }
      if (FLAGS_run_max_frames > 0) {
        args.insert(args.end(), {"--max_frames", std::to_string(FLAGS_run_max_frames)});
      }
      for (const std::string& set : context.config_overrides) {
        args.insert(args.end(), {"--set", set});
      }
      if (repeats > 1) {
        args.insert(args.end(), {"--set", "mapping.init_seed=" + std::to_string(pair.repeat)});
      }
      const auto start = std::chrono::steady_clock::now();
      pair.exit_code = RunProcess(args, pair.dir + "/log.txt");
      pair.ran = true;
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::lock_guard<std::mutex> lock(print_mutex);
      std::cout << "pldvo ablate: " << dataset_names[pair.dataset] << " x "
                << config_names[pair.config]
                << (repeats > 1 ? " seed " + std::to_string(pair.repeat) : std::string()) << ": "
                << (pair.exit_code == 0 ? "ok"
                                        : "FAILED (exit " + std::to_string(pair.exit_code) +
                                              ", see " + pair.dir + "/log.txt)")
                << " in " << std::fixed << std::setprecision(1) << seconds << " s" << std::endl;
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < std::max(1, FLAGS_jobs); ++j) threads.emplace_back(worker);
  for (std::thread& thread : threads) thread.join();

  // Results over the whole grid.
  std::vector<nlohmann::json> summaries(pairs.size());
  std::vector<std::string> statuses(pairs.size());
  for (Pair& pair : pairs) {
    summaries[pair.index] = ReadSummary(pair.dir);
    const bool have = summaries[pair.index].is_object();
    if (pair.ran && pair.exit_code != 0) {
      statuses[pair.index] = "failed_exit_" + std::to_string(pair.exit_code);
    } else if (!have) {
      statuses[pair.index] = pair.ran ? "failed_no_summary" : "not_run";
    } else if (!std::isfinite(JsonNumber(summaries[pair.index], "rpe_cm_s"))) {
      statuses[pair.index] = "no_rpe";
    } else {
      statuses[pair.index] = "ok";
    }
  }
  {
    std::ofstream csv(out + "/results.csv");
    csv << "dataset,config,status,frames,tracked,keyframes,lost_events,rpe_cm_s,rpe_deg_s,ate_m,"
           "coverage,scale_drift,ms_median_tracking_thread,ms_median_total,init_seed,dir,"
           "scale_segments,motion_direction_error_deg_median,motion_rotation_ratio,"
           "reanchored_rpe_cm_s,reanchored_rpe_deg_s,keyframes_ate_m_ba,rpe_cm_s_still\n";
    for (const Pair& pair : pairs) {
      const nlohmann::json& s = summaries[pair.index];
      auto integer = [&](const char* key) {
        const double v = JsonNumber(s, key);
        return std::isfinite(v) ? std::to_string(static_cast<long>(v)) : std::string();
      };
      const nlohmann::json ms =
          s.is_object() && s.contains("ms_median") ? s["ms_median"] : nlohmann::json();
      // The windowed BA's re-anchored trajectory (trajectory_ba.txt); a run without the BA has
      // only trajectory.txt, so BA and no-BA configs compare on one column.
      const bool ba = s.is_object() && s.contains("windowed_ba") &&
                      s["windowed_ba"].contains("reanchored_rpe_cm_s");
      const nlohmann::json& reanchored = ba ? s["windowed_ba"] : s;
      const char* rpe_key = ba ? "reanchored_rpe_cm_s" : "rpe_cm_s";
      const char* rpe_deg_key = ba ? "reanchored_rpe_deg_s" : "rpe_deg_s";
      csv << dataset_names[pair.dataset] << "," << config_names[pair.config] << ","
          << statuses[pair.index] << "," << integer("frames") << "," << integer("tracked") << ","
          << integer("keyframes") << "," << integer("lost_events") << ","
          << Fixed(JsonNumber(s, "rpe_cm_s"), 4) << "," << Fixed(JsonNumber(s, "rpe_deg_s"), 4)
          << "," << Fixed(JsonNumber(s, "ate_m"), 5) << "," << Fixed(JsonNumber(s, "coverage"), 3)
          << "," << Fixed(JsonNumber(s, "scale_drift"), 3) << ","
          << Fixed(JsonNumber(ms, "tracking_thread"), 2) << "," << Fixed(JsonNumber(ms, "total"), 2)
          << "," << (repeats > 1 ? std::to_string(pair.repeat) : std::string()) << "," << pair.dir
          << "," << integer("scale_segments") << ","
          << Fixed(JsonNumber(s, "motion_direction_error_deg_median"), 2) << ","
          << Fixed(JsonNumber(s, "motion_rotation_ratio"), 4) << ","
          << Fixed(JsonNumber(reanchored, rpe_key), 4) << ","
          << Fixed(JsonNumber(reanchored, rpe_deg_key), 4) << ","
          << Fixed(ba ? JsonNumber(reanchored, "keyframes_ate_m_ba") : std::nan(""), 5) << ","
          << Fixed(JsonNumber(s, "rpe_cm_s_still"), 4) << "\n";
    }
  }
  {
    std::ofstream md(out + "/results.md");
    auto table = [&](const std::string& title, const char* key, int precision) {
      md << "### " << title << "\n\n| sequence |";
      for (const std::string& name : config_names) md << " " << name << " |";
      md << "\n| --- |";
      for (size_t c = 0; c < configs.size(); ++c) md << " ---: |";
      md << "\n";
      for (size_t d = 0; d < datasets.size(); ++d) {
        md << "| " << dataset_names[d] << " |";
        for (size_t c = 0; c < configs.size(); ++c) {
          // The repeats of (d, c), and what each shows.
          std::vector<double> values;
          int failed = 0, not_run = 0, lost = 0;
          for (int r = 0; r < repeats; ++r) {
            const int k = static_cast<int>((d * configs.size() + c) * repeats + r);
            const std::string& status = statuses[k];
            if (status == "not_run") {
              ++not_run;
            } else if (status != "ok") {
              ++failed;
            } else {
              const nlohmann::json& s = summaries[k];
              const double value = std::string(key) == "ms"
                                       ? JsonNumber(s["ms_median"], "tracking_thread")
                                       : JsonNumber(s, key);
              if (std::isfinite(value)) values.push_back(value);
              const double lost_events = JsonNumber(s, "lost_events");
              if (std::isfinite(lost_events)) lost += static_cast<int>(lost_events);
            }
          }
          std::string cell;
          if (not_run == repeats) {
            cell = "-";
          } else if (values.empty()) {
            cell = "X";
          } else {
            cell = Fixed(Median(values), precision);
            if (repeats > 1) {
              cell += " [" + Fixed(*std::min_element(values.begin(), values.end()), precision) +
                      ", " + Fixed(*std::max_element(values.begin(), values.end()), precision) +
                      "]";
            }
            if (failed > 0) cell += " (" + std::to_string(failed) + " X)";
            if (std::string(key) == "rpe_cm_s" && lost > 0) {
              cell += " (" + std::to_string(lost) + " lost)";
            }
          }
          md << " " << cell << " |";
        }
        md << "\n";
      }
      md << "\n";
    };
    md << "## Ablation results\n\nX: the run failed (crashed, exited non-zero or too few poses to "
          "evaluate); -: not run in this shard. Sim(3)-aligned, RPE over 1 s intervals "
          "(docs/evaluation.md). Per-run outputs in runs/<sequence>__<config>/.";
    if (repeats > 1) {
      md << " Each cell: the median and [min, max] over " << repeats
         << " runs with mapping.init_seed = 1.." << repeats
         << " (runs/<sequence>__<config>__seed<k>/).";
    }
    md << "\n\n";
    table("RPE translation (cm/s)", "rpe_cm_s", 2);
    table(
        "RPE translation of an estimate that never moves (cm/s; the ground truth's own motion: "
        "a translational RPE near it was not tracked, docs/evaluation.md)",
        "rpe_cm_s_still", 2);
    table("RPE rotation (deg/s)", "rpe_deg_s", 3);
    table("ATE (m)", "ate_m", 4);
    table("Scale drift (max / min of the estimate's scale over 1 s windows)", "scale_drift", 2);
    table("Scale segments (a re-initialisation with a fresh random map starts one)",
          "scale_segments", 0);
    table(
        "Translation direction error of the frame-to-frame motions (deg, median over the frames; "
        "docs/evaluation.md)",
        "motion_direction_error_deg_median", 1);
    table(
        "Rotation ratio (estimated / true turning of the frame-to-frame motions; "
        "docs/evaluation.md)",
        "motion_rotation_ratio", 3);
    // With odometry.parallel_mapping false the tracking thread also runs every mapping job.
    const bool inline_mapping = std::any_of(summaries.begin(), summaries.end(), [](const auto& s) {
      return s.is_object() && s.contains("parallel_mapping") && s["parallel_mapping"] == false;
    });
    table(inline_mapping ? "Median tracking-thread time per frame (ms; mapping inline, included)"
                         : "Median tracking-thread time per frame (ms)",
          "ms", 1);
  }
  // results.json: the cells' statistics, machine-readable.
  {
    nlohmann::json cells = nlohmann::json::array();
    for (size_t d = 0; d < datasets.size(); ++d) {
      for (size_t c = 0; c < configs.size(); ++c) {
        nlohmann::json cell = {
            {"dataset", dataset_names[d]}, {"config", config_names[c]}, {"runs", repeats}};
        int ok = 0, failed = 0, not_run = 0, lost = 0;
        std::vector<std::vector<double>> values(5);
        const char* const keys[] = {"rpe_cm_s", "rpe_deg_s", "ate_m", "scale_drift",
                                    "ms_tracking_thread"};
        for (int r = 0; r < repeats; ++r) {
          const int k = static_cast<int>((d * configs.size() + c) * repeats + r);
          if (statuses[k] == "not_run") {
            ++not_run;
            continue;
          }
          if (statuses[k] != "ok") {
            ++failed;
            continue;
          }
          ++ok;
          const nlohmann::json& s = summaries[k];
          const double lost_events = JsonNumber(s, "lost_events");
          if (std::isfinite(lost_events)) lost += static_cast<int>(lost_events);
          for (int v = 0; v < 5; ++v) {
            const double value =
                v == 4 ? (s.contains("ms_median") ? JsonNumber(s["ms_median"], "tracking_thread")
                                                  : std::nan(""))
                       : JsonNumber(s, keys[v]);
            if (std::isfinite(value)) values[v].push_back(value);
          }
        }
        cell["ok"] = ok;
        cell["failed"] = failed;
        cell["not_run"] = not_run;
        cell["lost_events"] = lost;
        for (int v = 0; v < 5; ++v) {
          if (values[v].empty()) {
            cell[keys[v]] = nullptr;
            continue;
          }
          cell[keys[v]] = {{"median", Median(values[v])},
                           {"min", *std::min_element(values[v].begin(), values[v].end())},
                           {"max", *std::max_element(values[v].begin(), values[v].end())}};
        }
        cells.push_back(std::move(cell));
      }
    }
    const nlohmann::json results = {{"configs", config_names},
                                    {"datasets", dataset_names},
                                    {"repeats", repeats},
                                    {"cells", std::move(cells)}};
    std::ofstream(out + "/results.json") << results.dump(2) << "\n";
  }
  // Trajectory plots.
  for (size_t d = 0; d < datasets.size(); ++d) {
    try {
      DatasetOptions options;
      if (!FLAGS_camera.empty()) options.camera = FLAGS_camera;
      if (!gflags::GetCommandLineFlagInfoOrDie("format").is_default) options.format = FLAGS_format;
      const std::unique_ptr<Dataset> dataset = OpenDataset(datasets[d], options);
      std::vector<Eigen::Vector3d> gt_positions;
      const Trajectory* ground_truth = dataset->ground_truth();
      if (ground_truth != nullptr) {
        for (const StampedPose& pose : *ground_truth) {
          gt_positions.push_back(pose.world_from_cam.translation());
        }
      }
      std::vector<SvgCurve> curves;
      for (size_t c = 0; c < configs.size(); ++c) {
        const Pair& pair = pairs[(d * configs.size() + c) * repeats];
        if (!std::filesystem::exists(pair.dir + "/trajectory.txt")) continue;
        Trajectory estimate;
        try {
          estimate = ReadTrajectoryTum(pair.dir + "/trajectory.txt");
        } catch (const std::exception&) {
          continue;
        }
        SvgCurve curve;
        curve.label = config_names[c];
        Sim3Alignment gt_from_est;
        if (ground_truth != nullptr && !ground_truth->empty()) {
          try {
            gt_from_est = EvaluateTrajectory(*ground_truth, estimate).gt_from_est;
          } catch (const std::exception&) {
            curve.label += " (not aligned)";
          }
        }
        for (const StampedPose& pose : estimate) {
          curve.positions.push_back(gt_from_est * pose.world_from_cam.translation());
        }
        curves.push_back(std::move(curve));
      }
      WriteTrajectorySvg(out + "/trajectories_" + dataset_names[d] + ".svg",
                         dataset_names[d] + " (top view, Sim(3)-aligned)", gt_positions, curves);
    } catch (const std::exception& e) {
      std::cerr << "pldvo ablate: no trajectory plot for " << datasets[d] << ": " << e.what()
                << "\n";
    }
  }
  std::ifstream md(out + "/results.md");
  std::cout << md.rdbuf();
  bool all_ok = true;
  if (FLAGS_collect) {
    const long missing = std::count(statuses.begin(), statuses.end(), std::string("not_run"));
    if (missing > 0) {
      std::cerr << "pldvo ablate --collect: " << missing << " of " << pairs.size()
                << " runs have no summary.json in " << out << "/runs\n";
      all_ok = false;
    }
  }
  for (const Pair* pair : mine) all_ok = all_ok && pair->exit_code == 0;
  return all_ok ? 0 : 1;
}

}  // namespace

PLDVO_REGISTER_COMMAND("ablate",
                       "Run every (dataset, config) pair in subprocesses; results tables and "
                       "trajectory plots.",
                       RunAblate, "format", "camera", "out");

}  // namespace pldvo
