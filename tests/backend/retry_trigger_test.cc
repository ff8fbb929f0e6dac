// RetryTrigger (backend/odometry/retry_trigger.h): the photometric RMS decides, and a slow drift of
// the RMS cannot drag the running mean along and silence the retries.
#include "backend/odometry/retry_trigger.h"

#include <gtest/gtest.h>

namespace pldvo {
namespace {

TrackingResult Result(double rms, double photometric_rms) {
  TrackingResult result;
  result.status = TrackingStatus::kConverged;
  result.final_rms = rms;
  result.final_photometric_rms = photometric_rms;
  return result;
}

TEST(RetryTriggerTest, UsesThePhotometricRmsWhenThereIsOne) {
  EXPECT_EQ(RetryTrigger::Rms(Result(2.0, 1.5)), 1.5);
  EXPECT_EQ(RetryTrigger::Rms(Result(2.0, 0.0)), 2.0);  // lines only
  RetryTrigger trigger(1.5);
  trigger.Update(Result(1.0, 1.0));
  // The combined RMS is high, the photometric one is not: no retry; and the other way round.
  EXPECT_FALSE(trigger.ShouldRetry(Result(3.0, 1.2)));
  EXPECT_TRUE(trigger.ShouldRetry(Result(1.2, 1.6)));
  TrackingResult lost = Result(1.0, 1.0);
  lost.status = TrackingStatus::kLost;
  EXPECT_TRUE(trigger.ShouldRetry(lost));
}

TEST(RetryTriggerTest, FramesStuckInAWrongMinimumKeepRetrying) {
  // lowtex seed 2 (docs/odometry.md): the pose slides into a wrong minimum and the retries do
  // not get out of it for ~10 frames (until a wrong line match is dropped). Those frames' RMS
  // stays high; a plain running mean (0.9 mean + 0.1 rms) absorbs it and silences the retries
  // after 7 frames, the clamped mean grows by at most 5% per frame and keeps them going.
  RetryTrigger trigger(1.5);
  for (int i = 0; i < 20; ++i) trigger.Update(Result(1.0, 1.0));
  double plain_mean = 1.0;
  int retries = 0, plain_retries = 0;
  for (int frame = 0; frame < 20; ++frame) {
    const double rms = 3.0;
    retries += trigger.ShouldRetry(Result(rms, rms));
    plain_retries += rms > 1.5 * plain_mean;
    trigger.Update(Result(rms, rms));
    plain_mean = 0.9 * plain_mean + 0.1 * rms;
  }
  EXPECT_EQ(plain_retries, 7);
  EXPECT_GE(retries, 12);
  // A lasting change of the RMS level (e.g. lighting) is still followed.
  for (int frame = 0; frame < 20; ++frame) trigger.Update(Result(3.0, 3.0));
  EXPECT_FALSE(trigger.ShouldRetry(Result(3.0, 3.0)));
  EXPECT_NEAR(trigger.mean(), 3.0, 0.3);
}

}  // namespace
}  // namespace pldvo
