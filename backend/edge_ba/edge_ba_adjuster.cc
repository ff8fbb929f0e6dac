#include "backend/edge_ba/edge_ba_adjuster.h"

#include <exception>
#include <stdexcept>
#include <utility>

#include "backend/edge_ba/edge_ba_solver.h"

namespace pldvo {

EdgeBundleAdjuster::EdgeBundleAdjuster(const EdgeBAOptions& options, ResultCallback callback)
    : options_(options), callback_(std::move(callback)) {
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument(std::string(__FILE__) + ": EdgeBundleAdjuster: " + error);
  }
  worker_ = std::thread(&EdgeBundleAdjuster::Run, this);
}

EdgeBundleAdjuster::~EdgeBundleAdjuster() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    pending_.clear();
  }
  work_available_.notify_all();
  worker_.join();
}

long EdgeBundleAdjuster::Submit(EdgeBAWindow window) {
  CheckEdgeBAWindow(window);
  long sequence;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sequence = next_sequence_++;
    pending_.emplace_back(sequence, std::move(window));
    ++statistics_.submitted;
    while (static_cast<int>(pending_.size()) > options_.max_queue) {
      pending_.pop_front();
      ++statistics_.dropped_windows;
    }
  }
  work_available_.notify_one();
  return sequence;
}

std::optional<EdgeBAResult> EdgeBundleAdjuster::Poll() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (results_.empty()) return std::nullopt;
  EdgeBAResult result = std::move(results_.front());
  results_.pop_front();
  return result;
}

void EdgeBundleAdjuster::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return pending_.empty() && !busy_; });
}

EdgeBundleAdjuster::Statistics EdgeBundleAdjuster::statistics() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return statistics_;
}

void EdgeBundleAdjuster::Run() {
  for (;;) {
    std::pair<long, EdgeBAWindow> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_available_.wait(lock, [this] { return stop_ || !pending_.empty(); });
      if (stop_) break;
      job = std::move(pending_.front());
      pending_.pop_front();
      busy_ = true;
    }
    EdgeBAResult result;
    try {
      result = SolveEdgeBA(job.second, options_);
    } catch (const std::exception& error) {
      result = EdgeBAResult();
      result.message = error.what();
    }
    result.sequence = job.first;
    if (callback_) callback_(result);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      results_.push_back(std::move(result));
      while (static_cast<int>(results_.size()) > options_.max_queue) {
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

}  // namespace pldvo
