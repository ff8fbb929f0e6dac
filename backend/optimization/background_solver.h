// BackgroundSolver: a worker thread that solves submitted problems in order beside tracking
// (the edge BA's and the windowed BA's adjusters, docs/edge_ba.md and docs/windowed_ba.md).
//
// Submit() queues a problem (moved in) and returns its sequence number at once; the worker solves
// the queue in order and hands each result back through the callback (run on the worker thread)
// and/or Poll() (from any thread). Submit never waits for a solve: when more than max_queue
// problems are pending, the oldest pending one is dropped (a newer one supersedes it), and at
// most max_queue unpolled results are kept (oldest dropped). A solve that throws gives the result
// of on_error(what). Result has a `long sequence` member, set to the submission number.
// on_start, when given, runs first on the worker thread (e.g. to lower its priority).
#ifndef PLDVO_BACKEND_OPTIMIZATION_BACKGROUND_SOLVER_H_
#define PLDVO_BACKEND_OPTIMIZATION_BACKGROUND_SOLVER_H_

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace pldvo {

template <class Problem, class Result>
class BackgroundSolver {
 public:
  using Solve = std::function<Result(const Problem&)>;
  using OnError = std::function<Result(const std::string& what)>;
  using ResultCallback = std::function<void(const Result&)>;
  using OnStart = std::function<void()>;

  struct Statistics {
    long submitted = 0;
    long solved = 0;           // results produced (successful or not)
    long dropped_windows = 0;  // superseded in the queue before being solved
    long dropped_results = 0;  // not polled in time
  };

  // Starts the worker; max_queue >= 1.
  BackgroundSolver(int max_queue, Solve solve, OnError on_error, ResultCallback callback = nullptr,
                   OnStart on_start = nullptr)
      : max_queue_(max_queue),
        solve_(std::move(solve)),
        on_error_(std::move(on_error)),
        callback_(std::move(callback)),
        on_start_(std::move(on_start)),
        worker_(&BackgroundSolver::Run, this) {}
  // Finishes the problem being solved, discards pending ones, joins the worker.
  ~BackgroundSolver() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
      pending_.clear();
    }
    work_available_.notify_all();
    worker_.join();
  }
  BackgroundSolver(const BackgroundSolver&) = delete;
  BackgroundSolver& operator=(const BackgroundSolver&) = delete;

  long Submit(Problem problem) {
    long sequence;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      sequence = next_sequence_++;
      pending_.emplace_back(sequence, std::move(problem));
      ++statistics_.submitted;
      while (static_cast<int>(pending_.size()) > max_queue_) {
        pending_.pop_front();
        ++statistics_.dropped_windows;
      }
    }
    work_available_.notify_one();
    return sequence;
  }

  // The oldest unpolled result, or nothing.
  std::optional<Result> Poll() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (results_.empty()) return std::nullopt;
    Result result = std::move(results_.front());
    results_.pop_front();
    return result;
  }

  // Blocks until every queued problem has been solved.
  void WaitIdle() {
    std::unique_lock<std::mutex> lock(mutex_);
    idle_.wait(lock, [this] { return pending_.empty() && !busy_; });
  }

  Statistics statistics() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return statistics_;
  }

 private:
  void Run() {
    if (on_start_) on_start_();
    for (;;) {
      std::pair<long, Problem> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        work_available_.wait(lock, [this] { return stop_ || !pending_.empty(); });
        if (stop_) break;
        job = std::move(pending_.front());
        pending_.pop_front();
        busy_ = true;
      }
      Result result;
      try {
        result = solve_(job.second);
      } catch (const std::exception& error) {
        result = on_error_(error.what());
      }
      result.sequence = job.first;
      if (callback_) callback_(result);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        results_.push_back(std::move(result));
        while (static_cast<int>(results_.size()) > max_queue_) {
          results_.pop_front();
          ++statistics_.dropped_results;
        }
        ++statistics_.solved;
        busy_ = false;
      }
      idle_.notify_all();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }

  const int max_queue_;
  const Solve solve_;
  const OnError on_error_;
  const ResultCallback callback_;
  const OnStart on_start_;
  mutable std::mutex mutex_;
  std::condition_variable work_available_;
  std::condition_variable idle_;
  std::deque<std::pair<long, Problem>> pending_;
  std::deque<Result> results_;
  bool busy_ = false;
  bool stop_ = false;
  long next_sequence_ = 0;
  Statistics statistics_;
  std::thread worker_;  // last: starts after every member above is constructed
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_BACKGROUND_SOLVER_H_
