#include "backend/odometry/keyframe_window.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace pldvo {
namespace {

// A traced line's pixels widened across the segment lie up to half_width + 0.5 px from it; the
// rasterised centre pixels (the nearest pixel per step along the major axis) lie within 0.5 px
// measured along the minor axis, hence within 0.5 px perpendicular to the line.
constexpr double kCentrePixelDistance = 0.5 + 1e-9;

// The traced line's centre pixels, ordered along the segment, at most max_pixels of them evenly
// spaced (0 = all).
std::vector<Eigen::Vector2d> CentrePixels(const TracedLine& traced, int max_pixels) {
  std::vector<std::pair<double, Eigen::Vector2d>> along;
  for (const Eigen::Vector2i& p : traced.pixels) {
    const Eigen::Vector2d x = p.cast<double>();
    if (std::abs(traced.segment.SignedDistance(x)) <= kCentrePixelDistance) {
      along.emplace_back(traced.segment.Project(x), x);
    }
  }
  std::sort(along.begin(), along.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  const int n = static_cast<int>(along.size());
  const int keep = max_pixels > 0 ? std::min(n, max_pixels) : n;
  std::vector<Eigen::Vector2d> pixels;
  pixels.reserve(keep);
  for (int k = 0; k < keep; ++k) {
    const int i = keep == 1 ? 0 : static_cast<int>(static_cast<long>(k) * (n - 1) / (keep - 1));
    pixels.push_back(along[i].second);
  }
  return pixels;
}

}  // namespace

KeyframeWindow::KeyframeWindow(const PinholeCamera& camera, int size,
                               int max_pixels_per_observation)
    : camera_(camera), size_(size), max_pixels_(max_pixels_per_observation) {
  if (size_ < 2) throw std::invalid_argument("KeyframeWindow: size must be >= 2");
  if (max_pixels_ < 0) throw std::invalid_argument("KeyframeWindow: max_pixels must be >= 0");
}

void KeyframeWindow::AddKeyframe(int id, const SE3& world_from_kf, const EdgeTrace& edges,
                                 const std::vector<int>& previous_segment,
                                 const SE3* previous_from_kf) {
  if (!keyframes_.empty() && id <= keyframes_.back().id) {
    throw std::invalid_argument("KeyframeWindow::AddKeyframe: ids must increase");
  }
  Keyframe keyframe;
  keyframe.id = id;
  keyframe.world_from_kf = world_from_kf;
  keyframe.has_motion_prior = previous_from_kf != nullptr && !keyframes_.empty();
  if (keyframe.has_motion_prior) keyframe.previous_from_kf = *previous_from_kf;
  const Keyframe* previous = keyframes_.empty() ? nullptr : &keyframes_.back();
  for (const TracedLine& traced : edges.lines) {
    // Two pixels at least: a single pixel constrains a 3D line's projection in one direction only
    // and is usually a tracing artefact.
    std::vector<Eigen::Vector2d> pixels = CentrePixels(traced, max_pixels_);
    if (pixels.size() < 2) continue;
    int line_id = -1;
    if (previous != nullptr && traced.id >= 0 &&
        traced.id < static_cast<int>(previous_segment.size()) && previous_segment[traced.id] >= 0) {
      const auto it = previous->line_of_segment.find(previous_segment[traced.id]);
      if (it != previous->line_of_segment.end()) line_id = it->second;
    }
    if (line_id < 0) line_id = next_line_id_++;
    keyframe.line_of_segment[traced.id] = line_id;
    EdgeBAObservation observation;
    observation.line_id = line_id;
    observation.line_2d_id = traced.id;
    observation.pixels = std::move(pixels);
    keyframe.observations.push_back(std::move(observation));
  }
  keyframes_.push_back(std::move(keyframe));
  if (static_cast<int>(keyframes_.size()) > size_) {
    for (const auto& [segment, line_id] : keyframes_.front().line_of_segment) {
      departed_lines_.insert(line_id);
    }
    keyframes_.pop_front();
  }
  ForgetUnobservedLines();
}

void KeyframeWindow::ForgetUnobservedLines() {
  std::set<int> observed;
  for (const Keyframe& k : keyframes_) {
    for (const auto& [segment, line_id] : k.line_of_segment) observed.insert(line_id);
  }
  for (auto it = lines_.begin(); it != lines_.end();) {
    it = observed.count(it->first) ? std::next(it) : lines_.erase(it);
  }
  for (auto it = departed_lines_.begin(); it != departed_lines_.end();) {
    it = observed.count(*it) ? std::next(it) : departed_lines_.erase(it);
  }
}

void KeyframeWindow::Clear() {
  keyframes_.clear();
  lines_.clear();
  departed_lines_.clear();
  submitted_.clear();
}

EdgeBAWindow KeyframeWindow::MakeWindow() const {
  EdgeBAWindow window;
  window.camera = camera_;
  for (const Keyframe& k : keyframes_) {
    EdgeBAKeyframe keyframe;
    keyframe.id = k.id;
    keyframe.cam_from_world = k.world_from_kf.Inverse();
    keyframe.observations = k.observations;
    keyframe.has_motion_prior = k.has_motion_prior;
    keyframe.previous_from_this = k.previous_from_kf;
    window.keyframes.push_back(std::move(keyframe));
  }
  for (const auto& [id, line] : lines_) {
    EdgeBALine listed = line;
    listed.anchored = departed_lines_.count(id) > 0;
    window.lines.push_back(listed);
  }
  return window;
}

void KeyframeWindow::Remember(long sequence, const EdgeBAWindow& window) {
  std::map<int, SE3>& submitted = submitted_[sequence];
  submitted.clear();
  for (const EdgeBAKeyframe& k : window.keyframes) submitted[k.id] = k.cam_from_world.Inverse();
}

bool KeyframeWindow::Apply(const EdgeBAResult& result) {
  const auto snapshot = submitted_.find(result.sequence);
  if (snapshot == submitted_.end()) return false;
  const std::map<int, SE3> submitted = std::move(snapshot->second);
  submitted_.erase(submitted_.begin(), std::next(snapshot));
  if (!result.success || result.keyframes.empty()) return false;
  // Corrections world_new_from_world_old of the result keyframes, oldest first.
  std::vector<std::pair<int, SE3>> corrections;
  for (const EdgeBAResultKeyframe& k : result.keyframes) {
    const auto it = submitted.find(k.id);
    if (it == submitted.end()) continue;
    corrections.emplace_back(k.id, k.cam_from_world.Inverse() * it->second.Inverse());
  }
  if (corrections.empty()) return false;
  for (Keyframe& keyframe : keyframes_) {
    const SE3* correction = nullptr;
    for (const auto& [id, c] : corrections) {
      if (id <= keyframe.id) correction = &c;
    }
    if (correction != nullptr) keyframe.world_from_kf = *correction * keyframe.world_from_kf;
  }
  for (const EdgeBAResultLine& line : result.lines) {
    if (line.status == EdgeBALineStatus::kOptimized) lines_[line.line.id] = line.line;
  }
  ForgetUnobservedLines();
  return true;
}

bool KeyframeWindow::WorldFromKeyframe(int id, SE3* world_from_kf) const {
  for (const Keyframe& k : keyframes_) {
    if (k.id == id) {
      *world_from_kf = k.world_from_kf;
      return true;
    }
  }
  return false;
}

std::map<int, int> KeyframeWindow::LinesOfKeyframe(int id) const {
  for (const Keyframe& k : keyframes_) {
    if (k.id == id) return k.line_of_segment;
  }
  return {};
}

}  // namespace pldvo
