// The run loop over a dataset behind `pldvo run` (docs/odometry.md): the optional bootstraps,
// frame i + 1 loaded (and with odometry.frontend_thread prepared) while frame i is processed, the
// odometry, and the run's files, written as the run goes:
//   OUT/config.yaml      the effective config (`pldvo run --config OUT/config.yaml` repeats it);
//   OUT/trajectory.txt   TUM format, world_from_cam, dataset timestamps, one line per tracked
//                        frame, flushed per line (a crash never loses what was written);
//   OUT/groundtruth.txt  the dataset's ground truth (when it has one) in the same frame and
//                        format, so that evo compares the two files directly;
//   OUT/timing.csv       one row per frame: status, counts and the time of every component;
//   OUT/summary.json     at the end: counts, median / mean ms per component, peak and sampled
//                        memory (RSS), and with ground truth rpe_cm_s, rpe_deg_s, ate_m,
//                        coverage (Sim(3)-aligned), scale_drift and window_scales (1 s windows);
//   OUT/trajectory.svg   top view of the Sim(3)-aligned estimate over the ground truth;
//   OUT/trajectory_compare.txt  with odometry.compare_solver: the other solver's poses on the
//                        same tracking problems (summary.json `compare_solver`);
//   OUT/keyframes_ba.txt with backend.windowed_ba: every keyframe's pose after the last BA window
//                        that held it, TUM format, written at the end (summary.json
//                        `windowed_ba`). trajectory.txt keeps each frame as it was output: tracked
//                        against its keyframe as refined by the windows applied up to then;
//   OUT/trajectory_ba.txt with backend.windowed_ba: every tracked frame re-anchored to its
//                        keyframe's final pose (world_from_kf_final * kf_from_cam), at the end.
// A frame that fails to load is reported with its file, marked failed and skipped.
#ifndef PLDVO_BACKEND_ODOMETRY_SEQUENCE_RUNNER_H_
#define PLDVO_BACKEND_ODOMETRY_SEQUENCE_RUNNER_H_

#include <nlohmann/json.hpp>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/odometry/odometry_config.h"
#include "backend/odometry/odometry_observer.h"
#include "core/dataset.h"

namespace pldvo {

struct SequenceRunOptions {
  std::string out_dir;        // created when missing
  std::string dataset_label;  // the dataset as the user named it (trajectory header, summary)
  std::string config_label;   // the config file as the user named it (summary)
  int max_frames = 0;         // process only the first N frames (0 = all)
  bool progress = false;      // a progress bar on stderr
  // Frames fed at their timestamps as a live camera feeds them (LiveFrameSource): what the
  // odometry cannot take in time is dropped (summary.json `dropped_frames`).
  bool realtime = false;
};

// An output of the run could not be written (the run stops; what was written is kept).
class RunOutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An observer of the run that also adds to summary.json and to the run's report.
class RunObserver : public OdometryObserver {
 public:
  virtual void AddToSummary(nlohmann::json* /*summary*/) const {}
  // One line for the run's report ("" for none).
  virtual std::string ReportLine() const { return ""; }
};

struct SequenceRunResult {
  nlohmann::json summary;  // as written to summary.json
  int frames = 0;          // processed
  int tracked = 0;
  int failed = 0;  // failed to load or process
  // The per-component time table, the evaluation and the observer's line, for the console.
  std::vector<std::string> report;
};

class SequenceRunner {
 public:
  // `dataset` and `observer` (may be null) must outlive the runner.
  SequenceRunner(const Dataset& dataset, const OdometryConfig& config, SequenceRunOptions options,
                 RunObserver* observer = nullptr);

  // Runs the odometry over the dataset and writes the outputs. Throws RunOutputError when an
  // output cannot be written, std::invalid_argument for a config the odometry rejects.
  SequenceRunResult Run();

 private:
  const Dataset& dataset_;
  OdometryConfig config_;
  SequenceRunOptions options_;
  RunObserver* observer_;
};

// The run's console report: counts, the component table and the report lines.
void PrintRunReport(const SequenceRunResult& result, std::ostream& out);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_SEQUENCE_RUNNER_H_
