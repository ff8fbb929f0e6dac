#include "backend/odometry/mapping_worker.h"

#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <utility>

#include "backend/odometry/reference_builder.h"
#include "core/wall_clock.h"

namespace pldvo {

MappingWorker::MappingWorker(const PinholeCamera& camera, const MappingOptions& options,
                             bool parallel, int max_pending_updates, bool wait_when_behind, int lag)
    : camera_(camera),
      options_(options),
      parallel_(parallel),
      max_pending_updates_(std::max(1, max_pending_updates)),
      wait_when_behind_(wait_when_behind),
      lag_(std::max(0, lag)),
      mapper_(camera, options) {
  if (parallel_) thread_ = std::thread(&MappingWorker::ThreadLoop, this);
}

MappingWorker::~MappingWorker() {
  if (thread_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    job_ready_.notify_all();
    thread_.join();
  }
}

void MappingWorker::Submit(MappingJob job) {
  if (!parallel_) {
    if (job.kind == MappingJob::Kind::kUpdate) {
      held_back_.push_back(std::move(job));
      while (static_cast<int>(held_back_.size()) > lag_) RunOldestHeldBack();
    } else {
      Flush();
      Run(job);
    }
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // Real time: the oldest pending update makes room for the newest.
    const auto is_update = [](const QueuedJob& queued) {
      return queued.job.kind == MappingJob::Kind::kUpdate;
    };
    if (job.kind == MappingJob::Kind::kUpdate && !wait_when_behind_ &&
        std::count_if(queue_.begin(), queue_.end(), is_update) >= max_pending_updates_) {
      queue_.erase(std::find_if(queue_.begin(), queue_.end(), is_update));
      ++dropped_updates_;
    }
    ++submitted_seq_;
    if (job.kind != MappingJob::Kind::kUpdate) barrier_seq_ = submitted_seq_;
    queue_.push_back({submitted_seq_, std::move(job)});
  }
  job_ready_.notify_one();
}

std::shared_ptr<const KeyframeMap> MappingWorker::MapForTracking(int keyframe_id) {
  if (!parallel_) return Latest();                              // the held-back updates are the lag
  if (!wait_when_behind_) return WaitForKeyframe(keyframe_id);  // the latest, once keyframe_id's
  // Every job but the newest lag_ updates after the last other job, whatever ran since: the
  // inline schedule, so both modes give the same run.
  std::unique_lock<std::mutex> lock(mutex_);
  const int64_t required = RequiredSeq();
  job_done_.wait(lock, [&] { return done_seq_ >= required; });
  TrimHistory();
  return history_.empty() ? latest_ : history_.front().second;
}

int64_t MappingWorker::RequiredSeq() const { return std::max(barrier_seq_, submitted_seq_ - lag_); }

void MappingWorker::TrimHistory() {
  // Never asked for again: what precedes the newest state a tracking frame may still need.
  const int64_t required = RequiredSeq();
  while (history_.size() > 1 && history_[1].first <= required) history_.pop_front();
}

std::shared_ptr<const KeyframeMap> MappingWorker::Latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return latest_;
}

std::shared_ptr<const KeyframeMap> MappingWorker::WaitForKeyframe(int keyframe_id) {
  std::unique_lock<std::mutex> lock(mutex_);
  job_done_.wait(lock, [&] {
    return (latest_ != nullptr && latest_->keyframe_id == keyframe_id) ||
           failed_keyframe_id_ == keyframe_id || (queue_.empty() && !busy_);
  });
  return latest_;
}

void MappingWorker::RunOldestHeldBack() {
  const MappingJob job = std::move(held_back_.front());
  held_back_.pop_front();
  Run(job);
}

void MappingWorker::Flush() {
  if (!parallel_) {
    while (!held_back_.empty()) RunOldestHeldBack();
    return;
  }
  std::unique_lock<std::mutex> lock(mutex_);
  job_done_.wait(lock, [&] { return queue_.empty() && !busy_; });
}

std::vector<double> MappingWorker::JobTimesMs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return job_ms_;
}

double MappingWorker::TakeRecentJobMs() {
  std::lock_guard<std::mutex> lock(mutex_);
  const double ms = recent_job_ms_;
  recent_job_ms_ = 0.0;
  return ms;
}

int MappingWorker::dropped_updates() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_updates_;
}

int MappingWorker::failed_jobs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failed_jobs_;
}

int MappingWorker::line_depths_fused() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return line_depths_fused_;
}

int MappingWorker::line_depth_outliers() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return line_depth_outliers_;
}

FrameUpdateStats MappingWorker::stereo_counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stereo_counts_;
}

int MappingWorker::idepth_corrections_applied() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return idepth_corrections_applied_;
}

void MappingWorker::ThreadLoop() {
  while (true) {
    QueuedJob queued;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      job_ready_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stop_ and nothing left
      queued = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    Run(queued.job);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
      done_seq_ = queued.seq;
      if (wait_when_behind_) {
        history_.emplace_back(queued.seq, latest_);
        TrimHistory();
      }
    }
    job_done_.notify_all();
  }
}

void MappingWorker::Publish(std::shared_ptr<KeyframeMap> keyframe_map) {
  keyframe_map->reference = std::make_shared<const TrackingReference>(BuildReferencePoints(
      *keyframe_map->map, keyframe_levels_, camera_, options_.max_reference_points,
      options_.edge_foot_points ? mapper_.keyframe_lines() : std::vector<Eigen::Vector3d>()));
  keyframe_map->mean_idepth = MeanInverseDepth(*keyframe_map->map);
  keyframe_map->num_points =
      keyframe_map->reference->levels.empty()
          ? 0
          : static_cast<int>(keyframe_map->reference->levels[0].points.size());
  std::lock_guard<std::mutex> lock(mutex_);
  latest_ = std::move(keyframe_map);
}

void MappingWorker::InitializeRandomMap(const MappingJob& job, KeyframeMap* published) {
  mapper_.InitializeKeyframe(job.image, job.edges);
  published->random_init = true;
  updates_since_random_init_ = 0;
}

void MappingWorker::Run(const MappingJob& job) {
  const auto start = WallClock::now();
  // The regularised map of the state this job starts from, when known; a job that changes the
  // state leaves it unknown until it publishes.
  std::shared_ptr<const SemiDenseDepthMap> state_map = std::move(state_map_);
  try {
    auto published = std::make_shared<KeyframeMap>();
    switch (job.kind) {
      case MappingJob::Kind::kInitialize:
        if (!job.depth.empty()) {
          mapper_.InitializeKeyframeFromDepth(job.image, job.edges, job.depth,
                                              job.depth_idepth_var);
          updates_since_random_init_ = -1;
        } else {
          InitializeRandomMap(job, published.get());
        }
        keyframe_levels_ = ImagePyramid(job.image, job.num_levels);
        keyframe_id_ = job.keyframe_id;
        num_updates_ = 0;
        break;
      case MappingJob::Kind::kUpdate: {
        if (job.keyframe_id != keyframe_id_) {  // for a keyframe no longer current
          state_map_ = std::move(state_map);
          return;
        }
        const FrameUpdateStats counts = mapper_.UpdateWithFrame(
            InReferenceBrightness(job.image, job.brightness), job.cur_from_kf, job.lines_in_cur,
            job.pose_covariance, job.line_cov_scale);
        ++num_updates_;
        if (updates_since_random_init_ >= 0) ++updates_since_random_init_;
        std::lock_guard<std::mutex> lock(mutex_);
        stereo_counts_.AddCounts(counts);
        break;
      }
      case MappingJob::Kind::kLineDepths:
      case MappingJob::Kind::kIdepthCorrections: {
        if (job.keyframe_id != keyframe_id_) {  // for a keyframe no longer current
          state_map_ = std::move(state_map);
          return;
        }
        int fused = 0, outliers = 0, corrected = 0;
        if (job.kind == MappingJob::Kind::kLineDepths) {
          const LineDepthFusionStats stats = mapper_.FuseLineDepths(job.line_depths);
          fused = stats.fused;
          outliers = stats.outliers;
        } else {
          corrected = mapper_.ApplyIdepthCorrections(
              job.idepth_corrections, job.move_keyframe ? &job.new_from_old : nullptr,
              job.idepth_scale);
        }
        std::lock_guard<std::mutex> lock(mutex_);
        line_depths_fused_ += fused;
        line_depth_outliers_ += outliers;
        idepth_corrections_applied_ += corrected;
        // Often published right after the keyframe switch, before the odometry has read it: keep
        // what the switch reported (retired map, propagation, random init).
        if (latest_ != nullptr && latest_->keyframe_id == keyframe_id_) {
          published->retired_map = latest_->retired_map;
          published->retired_keyframe_id = latest_->retired_keyframe_id;
          published->propagation = latest_->propagation;
          published->random_init = latest_->random_init;
        }
        break;
      }
      case MappingJob::Kind::kNewKeyframe: {
        // The retired keyframe's final map is the one the last job published: propagated (and
        // kept) without smoothing and regularising the same state again.
        if (state_map == nullptr) {
          state_map = std::make_shared<const SemiDenseDepthMap>(
              mapper_.RegularizedMap(options_.regularize, options_.line_regularization));
        }
        if (job.keep_retired_map) {
          published->retired_map = state_map;
          published->retired_keyframe_id = keyframe_id_;
        }
        published->propagation = mapper_.PropagateToNewKeyframe(*state_map, job.image, job.edges,
                                                                job.new_from_old, job.brightness);
        if (mapper_.depth_map().CountValid() < job.min_propagated_points) {
          InitializeRandomMap(job, published.get());
        }
        keyframe_levels_ = ImagePyramid(job.image, job.num_levels);
        keyframe_id_ = job.keyframe_id;
        num_updates_ = 0;
        break;
      }
    }
    published->keyframe_id = keyframe_id_;
    published->num_updates = num_updates_;
    published->updates_since_random_init = updates_since_random_init_;
    published->map = std::make_shared<const SemiDenseDepthMap>(
        mapper_.RegularizedMap(options_.regularize, options_.line_regularization));
    state_map_ = published->map;
    Publish(std::move(published));
  } catch (const std::exception& e) {
    LOG(WARNING) << "mapping job for frame " << job.frame_index << " failed: " << e.what();
    std::lock_guard<std::mutex> lock(mutex_);
    ++failed_jobs_;
    if (job.kind == MappingJob::Kind::kInitialize || job.kind == MappingJob::Kind::kNewKeyframe) {
      failed_keyframe_id_ = job.keyframe_id;
    }
  }
  const double ms = MsSince(start);
  std::lock_guard<std::mutex> lock(mutex_);
  job_ms_.push_back(ms);
  recent_job_ms_ += ms;
}

}  // namespace pldvo
