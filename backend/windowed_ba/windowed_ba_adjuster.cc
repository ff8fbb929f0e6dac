#include "backend/windowed_ba/windowed_ba_adjuster.h"

#include <exception>
#include <stdexcept>
#include <string>
#include <utility>

namespace pldvo {

WindowedBundleAdjuster::WindowedBundleAdjuster(const WindowedBAOptions& options)
    : options_(options) {
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument(std::string(__FILE__) + ": WindowedBundleAdjuster: " + error);
  }
  worker_ = std::thread(&WindowedBundleAdjuster::Run, this);
}

WindowedBundleAdjuster::~WindowedBundleAdjuster() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    pending_.clear();
  }
  work_available_.notify_all();
  worker_.join();
}

long WindowedBundleAdjuster::Submit(WindowedBAWindow window) {
  CheckWindowedBAWindow(window);
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

std::optional<WindowedBAResult> WindowedBundleAdjuster::Poll() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (results_.empty()) return std::nullopt;
  WindowedBAResult result = std::move(results_.front());
  results_.pop_front();
  return result;
}

void WindowedBundleAdjuster::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return pending_.empty() && !busy_; });
}

WindowedBundleAdjuster::Statistics WindowedBundleAdjuster::statistics() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return statistics_;
}

void WindowedBundleAdjuster::Run() {
  for (;;) {
    std::pair<long, WindowedBAWindow> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_available_.wait(lock, [this] { return stop_ || !pending_.empty(); });
      if (stop_) break;
      job = std::move(pending_.front());
      pending_.pop_front();
      busy_ = true;
    }
    WindowedBAResult result;
    try {
      result = RunWindowedBA(job.second, options_);
    } catch (const std::exception& error) {
      result = WindowedBAResult();
      result.summary.message = error.what();
    }
    result.sequence = job.first;
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
