#include "backend/odometry/retry_trigger.h"

#include <algorithm>

namespace pldvo {

void RetryTrigger::Update(const TrackingResult& result) {
  const double rms = Rms(result);
  mean_ = mean_ > 0.0 ? 0.9 * mean_ + 0.1 * std::min(rms, ratio_ * mean_) : rms;
}

}  // namespace pldvo
