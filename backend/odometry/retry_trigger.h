// When the odometry retries a frame from alternative initial guesses (odometry.try_alternatives,
// docs/odometry.md): when the tracking result is lost, or when its RMS exceeds retry_rms_ratio
// times the running mean over recent tracked frames. The RMS is the photometric rows' when there
// are any: line rows treat an edge's pixels as independent although they share the line's
// error, so a wrong pose that the lines hold raises the combined RMS slowly. The mean follows a
// frame's RMS only up to ratio * mean, so a slow drift into a wrong minimum (RMS x1.13 per
// frame on lowtex seed 2) cannot raise the mean as fast as the RMS and silence the retries.
#ifndef PLDVO_BACKEND_ODOMETRY_RETRY_TRIGGER_H_
#define PLDVO_BACKEND_ODOMETRY_RETRY_TRIGGER_H_

#include "backend/tracking/tracker.h"

namespace pldvo {

class RetryTrigger {
 public:
  explicit RetryTrigger(double retry_rms_ratio) : ratio_(retry_rms_ratio) {}

  // The RMS the trigger uses.
  static double Rms(const TrackingResult& result) {
    return result.final_photometric_rms > 0.0 ? result.final_photometric_rms : result.final_rms;
  }
  // Whether `result` asks for alternative guesses.
  bool ShouldRetry(const TrackingResult& result) const {
    return result.status == TrackingStatus::kLost || (mean_ > 0.0 && Rms(result) > ratio_ * mean_);
  }
  // A tracked frame's final result: mean <- 0.9 mean + 0.1 min(rms, ratio * mean).
  void Update(const TrackingResult& result);
  double mean() const { return mean_; }

 private:
  double ratio_;
  double mean_ = 0.0;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_RETRY_TRIGGER_H_
