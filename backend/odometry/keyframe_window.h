// KeyframeWindow: the odometry's record of its newest keyframes for windowed edge bundle
// adjustment (docs/edge_ba.md, "In the odometry"). Per keyframe: its world_from_kf and its line
// observations (the central pixels of each traced segment), each associated with a 3D line id;
// per 3D line: the latest refined estimate. It builds the EdgeBAWindow snapshots and applies the
// results back.
//
// Association: a new keyframe's segment that the line matcher (verified by the tracked pose)
// matched to segment i of the previous keyframe inherits the 3D line id of segment i; any other
// segment gets a new id. Chains of such matches make one line of several keyframes.
//
// Applying a result (solved from the poses of a snapshot, possibly several keyframes ago): for
// every stored keyframe k, with r the newest result keyframe not newer than k,
//   world_from_kf_k <- (world_from_r_refined * world_from_r_submitted^-1) * world_from_kf_k,
// so result keyframes get their refined pose (when nothing changed them since the snapshot) and
// keyframes created after the snapshot move rigidly with the newest refined one.
#ifndef PLDVO_BACKEND_ODOMETRY_KEYFRAME_WINDOW_H_
#define PLDVO_BACKEND_ODOMETRY_KEYFRAME_WINDOW_H_

#include <deque>
#include <map>
#include <set>
#include <vector>

#include "backend/edge_ba/edge_ba_window.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "frontend/edge_tracer.h"

namespace pldvo {

class KeyframeWindow {
 public:
  // Keeps the newest `size` keyframes (>= 2). Observations keep at most
  // `max_pixels_per_observation` evenly spaced pixels (0 = all).
  KeyframeWindow(const PinholeCamera& camera, int size, int max_pixels_per_observation);

  // Appends a keyframe (id larger than every stored one) with its traced edges. previous_segment
  // [j] is the segment of the previous stored keyframe matched to this keyframe's segment j, or
  // -1 (may be shorter than the number of segments; missing entries are -1). previous_from_kf:
  // the tracked pose relative to the previous stored keyframe (the BA's motion prior), or null.
  // The oldest keyframe leaves when the window is full; lines it observed become anchored.
  void AddKeyframe(int id, const SE3& world_from_kf, const EdgeTrace& edges,
                   const std::vector<int>& previous_segment, const SE3* previous_from_kf);
  // Forgets every keyframe and line (e.g. after a re-initialisation at an extrapolated pose).
  void Clear();

  int size() const { return static_cast<int>(keyframes_.size()); }
  // The snapshot for EdgeBundleAdjuster / SolveEdgeBA: the stored keyframes oldest first, and
  // the refined estimates of their lines (anchored when also observed by departed keyframes).
  EdgeBAWindow MakeWindow() const;
  // Remembers the poses of a submitted snapshot under its sequence number, for Apply.
  void Remember(long sequence, const EdgeBAWindow& window);
  // Applies a successful result of the remembered snapshot `result.sequence` (see above) and
  // stores the optimised lines. Returns false (and changes nothing) for an unknown sequence or a
  // failed solve. Forgets that snapshot and every older one.
  bool Apply(const EdgeBAResult& result);
  // The stored pose of keyframe `id`; false when it is not in the window.
  bool WorldFromKeyframe(int id, SE3* world_from_kf) const;
  // The 3D line id of every associated segment (keyframe edge id) of keyframe `id`; empty when
  // it is not in the window.
  std::map<int, int> LinesOfKeyframe(int id) const;

 private:
  struct Keyframe {
    int id = -1;
    SE3 world_from_kf;
    std::map<int, int> line_of_segment;  // segment index -> 3D line id
    bool has_motion_prior = false;
    SE3 previous_from_kf;  // tracked, when has_motion_prior
    std::vector<EdgeBAObservation> observations;
  };

  // Drops estimates and departed marks of lines no stored keyframe observes.
  void ForgetUnobservedLines();

  PinholeCamera camera_;
  int size_;
  int max_pixels_;
  std::deque<Keyframe> keyframes_;  // oldest first
  int next_line_id_ = 0;
  std::map<int, EdgeBALine> lines_;  // refined estimates by 3D line id
  std::set<int> departed_lines_;     // observed by keyframes that left the window
  // Submitted snapshots: sequence -> (keyframe id -> world_from_kf at submission).
  std::map<long, std::map<int, SE3>> submitted_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_KEYFRAME_WINDOW_H_
