// EdgeBundleAdjuster: windowed edge bundle adjustment beside tracking (docs/edge_ba.md).
//
// The tracking thread Submit()s a snapshot of the newest keyframes (EdgeBAWindow, moved in) and
// goes on; a worker thread solves the snapshots in order (SolveEdgeBA) and hands each result
// back through the callback (run on the worker thread) and/or Poll() (from any thread).
// Submit never waits for a solve: when more than EdgeBAOptions::max_queue snapshots are pending,
// the oldest pending one is dropped (a newer window supersedes it), and at most max_queue
// unpolled results are kept (oldest dropped).
//
//   EdgeBundleAdjuster adjuster(options.backend.edge_ba);
//   adjuster.Submit(MakeWindow(keyframes));          // tracking thread, returns at once
//   while (auto result = adjuster.Poll()) Apply(*result);   // e.g. before the next keyframe
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_ADJUSTER_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_ADJUSTER_H_

#include <functional>
#include <optional>

#include "backend/edge_ba/edge_ba_options.h"
#include "backend/edge_ba/edge_ba_window.h"
#include "backend/optimization/background_solver.h"

namespace pldvo {

class EdgeBundleAdjuster {
 public:
  using ResultCallback = std::function<void(const EdgeBAResult&)>;
  using Statistics = BackgroundSolver<EdgeBAWindow, EdgeBAResult>::Statistics;

  // Starts the worker. Throws std::invalid_argument on invalid options.
  explicit EdgeBundleAdjuster(const EdgeBAOptions& options, ResultCallback callback = nullptr);
  EdgeBundleAdjuster(const EdgeBundleAdjuster&) = delete;
  EdgeBundleAdjuster& operator=(const EdgeBundleAdjuster&) = delete;

  // Checks the window (CheckEdgeBAWindow, throws std::invalid_argument on the caller's thread),
  // queues it and returns its sequence number (EdgeBAResult::sequence).
  long Submit(EdgeBAWindow window);
  // The oldest unpolled result, or nothing.
  std::optional<EdgeBAResult> Poll() { return solver_.Poll(); }
  // Blocks until every queued window has been solved (tests, benchmarks, end of a sequence).
  void WaitIdle() { solver_.WaitIdle(); }
  Statistics statistics() const { return solver_.statistics(); }

 private:
  const EdgeBAOptions options_;
  // Last: its worker reads options_; destroying it first finishes the window being solved,
  // discards pending ones and joins the worker.
  BackgroundSolver<EdgeBAWindow, EdgeBAResult> solver_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_ADJUSTER_H_
