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

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "backend/edge_ba/edge_ba_options.h"
#include "backend/edge_ba/edge_ba_window.h"

namespace pldvo {

class EdgeBundleAdjuster {
 public:
  using ResultCallback = std::function<void(const EdgeBAResult&)>;
  struct Statistics {
    long submitted = 0;
    long solved = 0;           // results produced (successful or not)
    long dropped_windows = 0;  // superseded in the queue before being solved
    long dropped_results = 0;  // not polled in time
  };

  // Starts the worker. Throws std::invalid_argument on invalid options.
  explicit EdgeBundleAdjuster(const EdgeBAOptions& options, ResultCallback callback = nullptr);
  // Finishes the window being solved, discards pending ones, joins the worker.
  ~EdgeBundleAdjuster();
  EdgeBundleAdjuster(const EdgeBundleAdjuster&) = delete;
  EdgeBundleAdjuster& operator=(const EdgeBundleAdjuster&) = delete;

  // Checks the window (CheckEdgeBAWindow, throws std::invalid_argument on the caller's thread),
  // queues it and returns its sequence number (EdgeBAResult::sequence).
  long Submit(EdgeBAWindow window);
  // The oldest unpolled result, or nothing.
  std::optional<EdgeBAResult> Poll();
  // Blocks until every queued window has been solved (tests, benchmarks, end of a sequence).
  void WaitIdle();
  Statistics statistics() const;

 private:
  void Run();

  const EdgeBAOptions options_;
  const ResultCallback callback_;
  mutable std::mutex mutex_;
  std::condition_variable work_available_;
  std::condition_variable idle_;
  std::deque<std::pair<long, EdgeBAWindow>> pending_;
  std::deque<EdgeBAResult> results_;
  bool busy_ = false;
  bool stop_ = false;
  long next_sequence_ = 0;
  Statistics statistics_;
  std::thread worker_;  // last: starts after every member above is constructed
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_ADJUSTER_H_
