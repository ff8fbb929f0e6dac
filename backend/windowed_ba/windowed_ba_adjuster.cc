#include "backend/windowed_ba/windowed_ba_adjuster.h"

#include <stdexcept>
#include <string>
#include <utility>

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
          }) {}

long WindowedBundleAdjuster::Submit(WindowedBAWindow window) {
  CheckWindowedBAWindow(window);
  return solver_.Submit(std::move(window));
}

}  // namespace pldvo
