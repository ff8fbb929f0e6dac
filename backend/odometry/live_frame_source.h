// Frames of a dataset delivered as a live camera delivers them (`pldvo run --realtime`): a
// camera thread releases frame i at its timestamp (relative to the first frame's, on the wall
// clock from Start), loads it (and with a preparer prepares it, the frontend thread's work) and
// puts it into a one-frame mailbox. A frame still in the mailbox when the next one arrives is
// dropped, as a camera driver drops what the application did not take in time; a frame whose
// successor is already due when its turn comes is dropped without loading, so that a slow
// loader never falls behind the camera.
#ifndef PLDVO_BACKEND_ODOMETRY_LIVE_FRAME_SOURCE_H_
#define PLDVO_BACKEND_ODOMETRY_LIVE_FRAME_SOURCE_H_

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <vector>

#include "core/dataset.h"

namespace pldvo {

template <class LoadedFrame>
class LiveFrameSource {
 public:
  // load(i) loads (and prepares) frame i; it runs on the camera thread.
  LiveFrameSource(const Dataset& dataset, int num_frames, std::function<LoadedFrame(int)> load)
      : dataset_(dataset), num_frames_(num_frames), load_(std::move(load)) {}
  ~LiveFrameSource() { Stop(); }
  LiveFrameSource(const LiveFrameSource&) = delete;
  LiveFrameSource& operator=(const LiveFrameSource&) = delete;

  void Start() {
    start_ = std::chrono::steady_clock::now();
    camera_ = std::thread([this] { RunCamera(); });
  }

  // The next delivered frame (index, frame), waiting for it; nullopt after the last one.
  std::optional<std::pair<int, LoadedFrame>> Next() {
    std::unique_lock<std::mutex> lock(mutex_);
    delivered_.wait(lock, [this] { return mailbox_.has_value() || finished_; });
    if (!mailbox_.has_value()) return std::nullopt;
    std::optional<std::pair<int, LoadedFrame>> frame = std::move(mailbox_);
    mailbox_.reset();
    return frame;
  }

  // Indices of the frames never delivered, in order (complete once Next returned nullopt).
  std::vector<int> dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<int> sorted = dropped_;
    std::sort(sorted.begin(), sorted.end());
    return sorted;
  }

  void Stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    stop_requested_.notify_all();
    if (camera_.joinable()) camera_.join();
  }

 private:
  std::chrono::steady_clock::time_point Due(int index) const {
    const double seconds = dataset_.timestamp(index) - dataset_.timestamp(0);
    return start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(seconds));
  }

  void RunCamera() {
    for (int i = 0; i < num_frames_; ++i) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        if (stop_requested_.wait_until(lock, Due(i), [this] { return stopping_; })) return;
      }
      if (i + 1 < num_frames_ && std::chrono::steady_clock::now() >= Due(i + 1)) {
        std::lock_guard<std::mutex> lock(mutex_);
        dropped_.push_back(i);
        continue;
      }
      LoadedFrame frame = load_(i);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (mailbox_.has_value()) dropped_.push_back(mailbox_->first);
        mailbox_.emplace(i, std::move(frame));
      }
      delivered_.notify_one();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
    }
    delivered_.notify_one();
  }

  const Dataset& dataset_;
  const int num_frames_;
  const std::function<LoadedFrame(int)> load_;
  std::chrono::steady_clock::time_point start_;
  std::thread camera_;
  mutable std::mutex mutex_;
  std::condition_variable delivered_;
  std::condition_variable stop_requested_;
  std::optional<std::pair<int, LoadedFrame>> mailbox_;
  std::vector<int> dropped_;
  bool finished_ = false;
  bool stopping_ = false;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_LIVE_FRAME_SOURCE_H_
