// Tests of LiveFrameSource (backend/odometry/live_frame_source.h): every frame is either
// delivered or dropped, delivered frames come in order, the last one always arrives, and a
// consumer that falls behind the camera loses the frames it could not take.
#include "backend/odometry/live_frame_source.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>
#include <vector>

namespace pldvo {
namespace {

// Timestamps only: the source never calls Load itself (its load function does).
class TimestampsOnly : public Dataset {
 public:
  TimestampsOnly(int frames, double interval_s) : frames_(frames), interval_s_(interval_s) {}
  std::string format() const override { return "timestamps"; }
  int size() const override { return frames_; }
  double timestamp(int i) const override { return 100.0 + i * interval_s_; }
  Frame Load(int /*i*/) const override { return Frame(); }
  const PinholeCamera& camera() const override { return camera_; }
  const Trajectory* ground_truth() const override { return nullptr; }

 private:
  int frames_;
  double interval_s_;
  PinholeCamera camera_;
};

// Delivered and dropped partition the frames; delivered ones are increasing; the last arrives.
void ExpectPartition(const std::vector<int>& delivered, const std::vector<int>& dropped,
                     int frames) {
  EXPECT_TRUE(std::is_sorted(delivered.begin(), delivered.end()));
  EXPECT_EQ(std::adjacent_find(delivered.begin(), delivered.end()), delivered.end());
  std::vector<int> all = delivered;
  all.insert(all.end(), dropped.begin(), dropped.end());
  std::sort(all.begin(), all.end());
  std::vector<int> expected(frames);
  for (int i = 0; i < frames; ++i) expected[i] = i;
  EXPECT_EQ(all, expected);
  ASSERT_FALSE(delivered.empty());
  EXPECT_EQ(delivered.back(), frames - 1);
}

TEST(LiveFrameSourceTest, EveryFrameIsDeliveredOrDroppedInOrder) {
  const TimestampsOnly dataset(20, 0.002);
  LiveFrameSource<int> source(dataset, dataset.size(), [](int index) { return 10 * index; });
  source.Start();
  std::vector<int> delivered;
  while (auto frame = source.Next()) {
    EXPECT_EQ(frame->second, 10 * frame->first);  // the load function's result, unchanged
    delivered.push_back(frame->first);
  }
  ExpectPartition(delivered, source.dropped(), dataset.size());
}

TEST(LiveFrameSourceTest, AConsumerThatFallsBehindLosesFrames) {
  // Ten frames 100 ms apart; the consumer takes the first it gets, then works 3 s: every later
  // frame but the last is due and replaced in the mailbox (or skipped) while it works.
  const TimestampsOnly dataset(10, 0.100);
  LiveFrameSource<int> source(dataset, dataset.size(), [](int index) { return index; });
  source.Start();
  std::vector<int> delivered;
  while (auto frame = source.Next()) {
    delivered.push_back(frame->first);
    if (delivered.size() == 1) std::this_thread::sleep_for(std::chrono::seconds(3));
  }
  ExpectPartition(delivered, source.dropped(), dataset.size());
  EXPECT_EQ(delivered.size(), 2u);
}

TEST(LiveFrameSourceTest, StoppingEarlyEndsTheCameraThread) {
  const TimestampsOnly dataset(1000, 1.0);  // 1000 s of frames: Stop must not wait for them
  LiveFrameSource<int> source(dataset, dataset.size(), [](int index) { return index; });
  source.Start();
  ASSERT_TRUE(source.Next().has_value());  // frame 0 is due at once
  source.Stop();
}

}  // namespace
}  // namespace pldvo
