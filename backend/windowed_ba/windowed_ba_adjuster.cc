#include "backend/windowed_ba/windowed_ba_adjuster.h"

#include <glog/logging.h>

#include <stdexcept>
#include <string>
#include <utility>

#include "backend/optimization/thread_priority.h"

namespace pldvo {
namespace {

const WindowedBAOptions& Checked(const WindowedBAOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument(std::string(__FILE__) + ": WindowedBundleAdjuster: " + error);
  }
  return options;
}

}  // namespace

WindowedBundleAdjuster::WindowedBundleAdjuster(const WindowedBAOptions& options)
    : options_(Checked(options)),
      solver_(
          options_.max_queue,
          [this](const WindowedBAWindow& window) { return RunWindowedBA(window, options_); },
          [](const std::string& what) {
            WindowedBAResult result;
            result.summary.message = what;
            return result;
          },
          nullptr,
          [this] {
            const std::string error = SetCurrentThreadPriority(options_.worker_priority);
            if (!error.empty()) LOG(WARNING) << "windowed BA worker_priority: " << error;
          }) {}

long WindowedBundleAdjuster::Submit(WindowedBAWindow window) {
  CheckWindowedBAWindow(window);
  return solver_.Submit(std::move(window));
}

}  // namespace pldvo
