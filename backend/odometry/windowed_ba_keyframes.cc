#include "backend/odometry/windowed_ba_keyframes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/statistics.h"

namespace pldvo {
namespace {

// I = e^a L + b in the radiance of `base` (I_base = e^{a_base} L + b_base taken as L'):
// a' = a - a_base, b' = b - e^{a'} b_base.
AffineBrightness Rebase(const AffineBrightness& brightness, const AffineBrightness& base) {
  AffineBrightness out;
  out.a = brightness.a - base.a;
  out.b = brightness.b - std::exp(out.a) * base.b;
  return out;
}

}  // namespace

WindowedBAKeyframes::WindowedBAKeyframes(const PinholeCamera& camera, int size,
                                         LeavingKeyframe leaving, double min_visible)
    : camera_(camera), size_(size), leaving_(leaving), min_visible_(min_visible) {
  if (size_ < 2) throw std::invalid_argument("WindowedBAKeyframes: size must be >= 2");
}

void WindowedBAKeyframes::AddKeyframe(int id, int frame_index, double timestamp,
                                      const SE3& world_from_kf, const cv::Mat& image,
                                      const std::vector<LineSegment>& segments,
                                      const std::vector<int>& previous_segment,
                                      const AffineBrightness& brightness_from_previous) {
  if (!keyframes_.empty() && id <= keyframes_.back().record.id) {
    throw std::invalid_argument("WindowedBAKeyframes::AddKeyframe: ids must increase");
  }
  Keyframe keyframe;
  keyframe.record.id = id;
  keyframe.record.frame_index = frame_index;
  keyframe.record.timestamp = timestamp;
  keyframe.record.world_from_kf = world_from_kf;
  keyframe.pyramid = std::make_shared<const ImagePyramid>(image, 1);
  keyframe.segments = segments;
  const Keyframe* previous = keyframes_.empty() ? nullptr : &keyframes_.back();
  if (previous != nullptr) {
    // I = e^a I_prev + b with I_prev = e^{a_prev} L + b_prev.
    keyframe.brightness.a = brightness_from_previous.a + previous->brightness.a;
    keyframe.brightness.b =
        std::exp(brightness_from_previous.a) * previous->brightness.b + brightness_from_previous.b;
  }
  keyframe.line_of_segment.assign(segments.size(), -1);
  for (size_t j = 0; j < segments.size(); ++j) {
    int line_id = -1;
    if (previous != nullptr && j < previous_segment.size() && previous_segment[j] >= 0 &&
        previous_segment[j] < static_cast<int>(previous->line_of_segment.size())) {
      line_id = previous->line_of_segment[previous_segment[j]];
    }
    keyframe.line_of_segment[j] = line_id >= 0 ? line_id : next_line_id_++;
  }
  keyframes_.push_back(std::move(keyframe));
  while (static_cast<int>(keyframes_.size()) > size_) {
    std::vector<LeavingCandidate> candidates(keyframes_.size());
    for (size_t k = 0; k < keyframes_.size(); ++k) {
      candidates[k].centre = keyframes_[k].record.world_from_kf.translation();
      if (leaving_ == LeavingKeyframe::kSpread && k + 2 < keyframes_.size()) {
        candidates[k].visible_in_newest = VisibleInNewest(keyframes_[k]);
      }
    }
    // The newest two stay: the previous keyframe's final map is still to come (SetPoints).
    const int leaving = ChooseLeavingKeyframe(candidates, leaving_, 2, min_visible_);
    departed_.push_back(keyframes_[leaving].record);
    keyframes_.erase(keyframes_.begin() + leaving);
  }
}

double WindowedBAKeyframes::VisibleInNewest(const Keyframe& keyframe) const {
  if (keyframe.points == nullptr || keyframe.points->empty()) return -1.0;
  const SE3 newest_from_kf =
      keyframes_.back().record.world_from_kf.Inverse() * keyframe.record.world_from_kf;
  const std::vector<WindowedBAPoint>& points = *keyframe.points;
  const size_t step = std::max<size_t>(1, points.size() / 2000);
  int seen = 0;
  int tried = 0;
  for (size_t i = 0; i < points.size(); i += step) {
    ++tried;
    const Eigen::Vector3d in_newest =
        newest_from_kf * (camera_.Unproject(points[i].pixel) / points[i].idepth);
    seen += in_newest.z() > 0.0 && camera_.IsInside(camera_.Project(in_newest), 0.0);
  }
  return static_cast<double>(seen) / tried;
}

void WindowedBAKeyframes::Clear() {
  for (const Keyframe& keyframe : keyframes_) departed_.push_back(keyframe.record);
  keyframes_.clear();
  submitted_.clear();
  prior_.reset();
}

std::vector<WindowedBAPoint> ObservedWindowPoints(const SemiDenseDepthMap& map) {
  std::vector<WindowedBAPoint> points;
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const int i = map.Index(x, y);
      if (!map.observed(i) || !(map.idepth_var(i) > 0.f) || !std::isfinite(map.idepth(i))) {
        continue;
      }
      WindowedBAPoint point;
      point.pixel = Eigen::Vector2d(x, y);
      point.idepth = map.idepth(i);
      point.idepth_var = map.idepth_var(i);
      point.edge_id = map.edge_id(i);
      points.push_back(point);
    }
  }
  return points;
}

bool WindowedBAKeyframes::SetPoints(int id, const SemiDenseDepthMap& map) {
  if (map.width() != camera_.width || map.height() != camera_.height) return false;
  for (Keyframe& keyframe : keyframes_) {
    if (keyframe.record.id != id) continue;
    keyframe.points = std::make_shared<std::vector<WindowedBAPoint>>(ObservedWindowPoints(map));
    return true;
  }
  return false;
}

bool WindowedBAKeyframes::Ready() const {
  if (keyframes_.size() < 2 || keyframes_.back().points == nullptr) return false;
  int with_points = 0;
  for (const Keyframe& keyframe : keyframes_) with_points += keyframe.points != nullptr;
  return with_points >= 2;
}

WindowedBAWindow WindowedBAKeyframes::MakeWindow() const {
  WindowedBAWindow window;
  window.camera = camera_;
  window.prior = prior_;
  std::vector<const Keyframe*> used;
  for (const Keyframe& keyframe : keyframes_) {
    if (keyframe.points != nullptr) used.push_back(&keyframe);
  }
  if (used.empty()) return window;
  const AffineBrightness base = used.front()->brightness;
  for (const Keyframe* keyframe : used) {
    WindowedBAKeyframe out;
    out.id = keyframe->record.id;
    out.cam_from_world = keyframe->record.world_from_kf.Inverse();
    out.brightness = Rebase(keyframe->brightness, base);
    out.pyramid = keyframe->pyramid;
    out.points = *keyframe->points;
    // Line observations: each segment of this keyframe in every other keyframe observing its
    // line (eq. 3 rows for the points on the segment's edge).
    for (size_t s = 0; s < keyframe->segments.size(); ++s) {
      for (const Keyframe* target : used) {
        if (target == keyframe) continue;
        for (size_t t = 0; t < target->segments.size(); ++t) {
          if (target->line_of_segment[t] != keyframe->line_of_segment[s]) continue;
          WindowedBALineObservation observation;
          observation.edge_id = static_cast<int>(s);
          observation.target_id = target->record.id;
          observation.line_in_target.line = target->segments[t].line;
          observation.line_in_target.cov = target->segments[t].line_cov;
          out.line_observations.push_back(observation);
        }
      }
    }
    window.keyframes.push_back(std::move(out));
  }
  return window;
}

void WindowedBAKeyframes::Remember(long sequence, const WindowedBAWindow& window) {
  Snapshot& snapshot = submitted_[sequence];
  snapshot = Snapshot();
  for (const WindowedBAKeyframe& k : window.keyframes) {
    snapshot.world_from_kf[k.id] = k.cam_from_world.Inverse();
    for (const Keyframe& keyframe : keyframes_) {
      if (keyframe.record.id == k.id) snapshot.points[k.id] = keyframe.points;
    }
  }
}

bool WindowedBAKeyframes::Apply(const WindowedBAResult& result, int corrections_id,
                                std::vector<IdepthCorrection>* corrections_of,
                                double* idepth_scale_of) {
  if (idepth_scale_of != nullptr) *idepth_scale_of = 1.0;
  const auto found = submitted_.find(result.sequence);
  if (found == submitted_.end()) return false;
  const Snapshot snapshot = std::move(found->second);
  submitted_.erase(submitted_.begin(), std::next(found));
  const SolverSummary& summary = result.summary;
  if (result.keyframes.empty() || result.points.empty() || !std::isfinite(summary.final_cost) ||
      summary.final_cost > summary.initial_cost) {
    return false;
  }
  // Corrections world_new_from_world_old of the result keyframes, oldest first.
  std::vector<std::pair<int, SE3>> corrections;
  for (const WindowedBAResultKeyframe& k : result.keyframes) {
    const auto it = snapshot.world_from_kf.find(k.id);
    if (it == snapshot.world_from_kf.end()) continue;
    corrections.emplace_back(k.id, k.cam_from_world.Inverse() * it->second.Inverse());
  }
  if (corrections.empty()) return false;
  for (Keyframe& keyframe : keyframes_) {
    const SE3* correction = nullptr;
    for (const auto& [id, c] : corrections) {
      if (id <= keyframe.record.id) correction = &c;
    }
    if (correction == nullptr) continue;
    keyframe.record.world_from_kf = *correction * keyframe.record.world_from_kf;
    ++keyframe.record.windows;
  }
  // Inverse depths: per host keyframe whose points are still the snapshot's, a new points
  // vector (the snapshot's stays as it was for older pending snapshots).
  std::map<int, std::vector<const WindowedBAResultPoint*>> by_host;
  for (const WindowedBAResultPoint& point : result.points)
    by_host[point.keyframe_id].push_back(&point);
  for (Keyframe& keyframe : keyframes_) {
    const auto host = by_host.find(keyframe.record.id);
    const auto submitted = snapshot.points.find(keyframe.record.id);
    if (host == by_host.end() || submitted == snapshot.points.end() ||
        submitted->second == nullptr || submitted->second != keyframe.points) {
      continue;
    }
    const std::vector<WindowedBAPoint>& before = *submitted->second;
    auto points = std::make_shared<std::vector<WindowedBAPoint>>(before);
    std::vector<double> ratios;
    for (const WindowedBAResultPoint* point : host->second) {
      if (point->point_index < 0 || point->point_index >= static_cast<int>(before.size()) ||
          !(point->idepth > 0.0) || !std::isfinite(point->idepth)) {
        continue;
      }
      const WindowedBAPoint& old_point = before[point->point_index];
      (*points)[point->point_index].idepth = point->idepth;
      if (keyframe.record.id != corrections_id) continue;
      if (corrections_of != nullptr) {
        corrections_of->push_back({static_cast<int>(old_point.pixel.y()) * camera_.width +
                                       static_cast<int>(old_point.pixel.x()),
                                   point->idepth - old_point.idepth});
      }
      if (old_point.idepth > 0.0) ratios.push_back(point->idepth / old_point.idepth);
    }
    keyframe.points = std::move(points);
    if (idepth_scale_of != nullptr && static_cast<int>(ratios.size()) >= kMinScalePoints) {
      *idepth_scale_of = UpperMedian(std::move(ratios));
    }
  }
  if (result.prior != nullptr) prior_ = result.prior;
  return true;
}

bool WindowedBAKeyframes::WorldFromKeyframe(int id, SE3* world_from_kf) const {
  for (const Keyframe& keyframe : keyframes_) {
    if (keyframe.record.id == id) {
      *world_from_kf = keyframe.record.world_from_kf;
      return true;
    }
  }
  return false;
}

bool WindowedBAKeyframes::WorldFromPreviousKeyframe(int id, SE3* world_from_previous) const {
  for (size_t k = 1; k < keyframes_.size(); ++k) {
    if (keyframes_[k].record.id == id) {
      *world_from_previous = keyframes_[k - 1].record.world_from_kf;
      return true;
    }
  }
  return false;
}

std::vector<KeyframePoseRecord> WindowedBAKeyframes::Recorded() const {
  std::vector<KeyframePoseRecord> records;
  for (const Keyframe& keyframe : keyframes_) records.push_back(keyframe.record);
  return records;
}

}  // namespace pldvo
