// WindowedBundleAdjuster: windowed photometric + line bundle adjustment beside tracking
// (docs/windowed_ba.md, "In the odometry"), as EdgeBundleAdjuster does for the edge BA.
//
// The tracking thread Submit()s a snapshot of the newest keyframes (WindowedBAWindow, moved in:
// its pyramids are shared and immutable) and goes on; a worker thread solves the snapshots in
// order (RunWindowedBA) and hands each result back through Poll(). Submit never waits for a
// solve: when more than WindowedBAOptions::max_queue snapshots are pending, the oldest pending
// one is dropped (a newer window supersedes it), and at most max_queue unpolled results are kept
// (oldest dropped).
//
//   WindowedBundleAdjuster adjuster(options.backend.windowed_ba);
//   adjuster.Submit(std::move(window));                       // returns at once
//   while (auto result = adjuster.Poll()) Apply(*result);     // e.g. at the next frame
#ifndef PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_ADJUSTER_H_
#define PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_ADJUSTER_H_

#include <optional>

#include "backend/optimization/background_solver.h"
#include "backend/windowed_ba/windowed_ba_options.h"
#include "backend/windowed_ba/windowed_ba_solver.h"
#include "backend/windowed_ba/windowed_ba_window.h"

namespace pldvo {

class WindowedBundleAdjuster {
 public:
  using Statistics = BackgroundSolver<WindowedBAWindow, WindowedBAResult>::Statistics;

  // Starts the worker. Throws std::invalid_argument on invalid options.
  explicit WindowedBundleAdjuster(const WindowedBAOptions& options);
  WindowedBundleAdjuster(const WindowedBundleAdjuster&) = delete;
  WindowedBundleAdjuster& operator=(const WindowedBundleAdjuster&) = delete;

  // Checks the window (CheckWindowedBAWindow, throws std::invalid_argument on the caller's
  // thread), queues it and returns its sequence number (WindowedBAResult::sequence).
  long Submit(WindowedBAWindow window);
  // The oldest unpolled result, or nothing.
  std::optional<WindowedBAResult> Poll() { return solver_.Poll(); }
  // Blocks until every queued window has been solved (tests, end of a sequence).
  void WaitIdle() { solver_.WaitIdle(); }
  Statistics statistics() const { return solver_.statistics(); }

 private:
  const WindowedBAOptions options_;
  // Last: its worker reads options_; destroying it first finishes the window being solved,
  // discards pending ones and joins the worker.
  BackgroundSolver<WindowedBAWindow, WindowedBAResult> solver_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_ADJUSTER_H_
