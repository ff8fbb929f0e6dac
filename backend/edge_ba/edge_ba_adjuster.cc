#include "backend/edge_ba/edge_ba_adjuster.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "backend/edge_ba/edge_ba_solver.h"

namespace pldvo {
namespace {

const EdgeBAOptions& Checked(const EdgeBAOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) {
    throw std::invalid_argument(std::string(__FILE__) + ": EdgeBundleAdjuster: " + error);
  }
  return options;
}

}  // namespace

EdgeBundleAdjuster::EdgeBundleAdjuster(const EdgeBAOptions& options, ResultCallback callback)
    : options_(Checked(options)),
      solver_(
          options_.max_queue,
          [this](const EdgeBAWindow& window) { return SolveEdgeBA(window, options_); },
          [](const std::string& what) {
            EdgeBAResult result;
            result.message = what;
            return result;
          },
          std::move(callback)) {}

long EdgeBundleAdjuster::Submit(EdgeBAWindow window) {
  CheckEdgeBAWindow(window);
  return solver_.Submit(std::move(window));
}

}  // namespace pldvo
