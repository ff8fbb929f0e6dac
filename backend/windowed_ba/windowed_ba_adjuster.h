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

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "backend/windowed_ba/windowed_ba_options.h"
#include "backend/windowed_ba/windowed_ba_solver.h"
#include "backend/windowed_ba/windowed_ba_window.h"

namespace pldvo {

class WindowedBundleAdjuster {
 public:
  struct Statistics {
    long submitted = 0;
    long solved = 0;           // results produced (successful or not)
    long dropped_windows = 0;  // superseded in the queue before being solved
    long dropped_results = 0;  // not polled in time
  };

  // Starts the worker. Throws std::invalid_argument on invalid options.
  explicit WindowedBundleAdjuster(const WindowedBAOptions& options);
  // Finishes the window being solved, discards pending ones, joins the worker.
  ~WindowedBundleAdjuster();
  WindowedBundleAdjuster(const WindowedBundleAdjuster&) = delete;
  WindowedBundleAdjuster& operator=(const WindowedBundleAdjuster&) = delete;

  // Checks the window (CheckWindowedBAWindow, throws std::invalid_argument on the caller's
  // thread), queues it and returns its sequence number (WindowedBAResult::sequence).
  long Submit(WindowedBAWindow window);
  // The oldest unpolled result, or nothing.
  std::optional<WindowedBAResult> Poll();
  // Blocks until every queued window has been solved (tests, end of a sequence).
  void WaitIdle();
  Statistics statistics() const;

 private:
  void Run();

  const WindowedBAOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable work_available_;
  std::condition_variable idle_;
  std::deque<std::pair<long, WindowedBAWindow>> pending_;
  std::deque<WindowedBAResult> results_;
  bool busy_ = false;
  bool stop_ = false;
  long next_sequence_ = 0;
  Statistics statistics_;
  std::thread worker_;  // last: starts after every member above is constructed
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_ADJUSTER_H_
