// WindowedBAKeyframes: the odometry's record of its newest keyframes for windowed photometric +
// line bundle adjustment (docs/windowed_ba.md, "In the odometry"). Per keyframe: world_from_kf,
// its image (a one-level pyramid, shared with the snapshots), its brightness relative to the
// oldest recorded keyframe, the semi-dense points of its depth map (the observed hypotheses of
// the published, regularised map) and its line segments, each associated with a line id. It
// builds the WindowedBAWindow snapshots and applies the results back.
//
// Line association (as KeyframeWindow does for the edge BA): a new keyframe's segment that the
// line matcher (verified by the tracked pose) matched to segment i of the previous keyframe
// inherits segment i's line id; chains of matches make one line of several keyframes. A point on
// edge e of host h gets a line observation in every other keyframe with a segment of e's line.
//
// Applying a result solved from the poses of a snapshot (possibly several keyframes ago): for
// every recorded keyframe k, with r the newest result keyframe not newer than k,
//   world_from_kf_k <- (world_from_r_refined * world_from_r_submitted^-1) * world_from_kf_k,
// so result keyframes get their refined pose and keyframes created after the snapshot move
// rigidly with the newest refined one. Inverse depths: each optimised point's correction
// (refined - submitted) is added to the recorded point, when the keyframe's points are still
// the ones of the snapshot (not replaced by a newer map since).
#ifndef PLDVO_BACKEND_ODOMETRY_WINDOWED_BA_KEYFRAMES_H_
#define PLDVO_BACKEND_ODOMETRY_WINDOWED_BA_KEYFRAMES_H_

#include <deque>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/windowed_ba/leaving_keyframe.h"
#include "backend/windowed_ba/windowed_ba_solver.h"
#include "backend/windowed_ba/windowed_ba_window.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "frontend/line_segment.h"
#include "residuals/affine_brightness.h"

namespace pldvo {

// A keyframe pose for the output: as tracked, or after the last BA window that held it.
struct KeyframePoseRecord {
  int id = -1;
  int frame_index = -1;
  double timestamp = 0.0;
  SE3 world_from_kf;
  int windows = 0;  // applied BA results that moved it
};

// The windowed BA's candidate points of a keyframe's depth map: its observed hypotheses with a
// finite inverse depth and a positive variance, row by row. Random initial guesses and
// hole-filled hypotheses carry no information for the BA's inverse-depth prior.
std::vector<WindowedBAPoint> ObservedWindowPoints(const SemiDenseDepthMap& map);

class WindowedBAKeyframes {
 public:
  // Keeps `size` keyframes (>= 2; throws std::invalid_argument otherwise): the newest, or with
  // LeavingKeyframe::kSpread the newest two and those DSO's choice keeps (leaving_keyframe.h).
  WindowedBAKeyframes(const PinholeCamera& camera, int size,
                      LeavingKeyframe leaving = LeavingKeyframe::kOldest,
                      double min_visible = 0.05);

  // Appends a keyframe (id larger than every recorded one) without points (SetPoints).
  // previous_segment[j]: the previous recorded keyframe's segment matched to segment j, or -1
  // (may be shorter; missing entries are -1). brightness_from_previous: its image relative to the
  // previous keyframe's (I = e^a I_prev + b). When the window is full one keyframe leaves (the
  // oldest, or as `leaving` chooses; its record moves to Departed()).
  void AddKeyframe(int id, int frame_index, double timestamp, const SE3& world_from_kf,
                   const cv::Mat& image, const std::vector<LineSegment>& segments,
                   const std::vector<int>& previous_segment,
                   const AffineBrightness& brightness_from_previous);
  // Forgets every keyframe (their records move to Departed()) and the prior, e.g. after a
  // re-initialisation at an extrapolated pose.
  void Clear();
  // The points of keyframe `id` from its depth map (observed hypotheses with a positive
  // variance); false when `id` is not recorded or the map's size is not the camera's.
  bool SetPoints(int id, const SemiDenseDepthMap& map);

  int size() const { return static_cast<int>(keyframes_.size()); }
  // At least two keyframes, the newest with points.
  bool Ready() const;
  // The snapshot: the recorded keyframes that have points, oldest first.
  WindowedBAWindow MakeWindow() const;
  // Remembers the poses and points of a submitted snapshot under its sequence number.
  void Remember(long sequence, const WindowedBAWindow& window);
  // Applies a result of the remembered snapshot `result.sequence` (see above) when its solve
  // produced poses and did not raise the cost; its prior (if any) goes with the next snapshots.
  // Returns false (and changes nothing) otherwise.
  // Forgets that snapshot and every older one. `corrections_of` (may be null) receives the
  // inverse-depth corrections of keyframe `corrections_id`'s optimised points, `idepth_scale_of`
  // (may be null) the median of their refined / submitted inverse depths: the BA's scale against
  // the map's (1 with fewer than kMinScalePoints of them).
  static constexpr int kMinScalePoints = 20;
  bool Apply(const WindowedBAResult& result, int corrections_id,
             std::vector<IdepthCorrection>* corrections_of, double* idepth_scale_of = nullptr);
  bool WorldFromKeyframe(int id, SE3* world_from_kf) const;
  // The pose of the keyframe recorded just before `id`; false when there is none.
  bool WorldFromPreviousKeyframe(int id, SE3* world_from_previous) const;
  // Records of keyframes that left the window, in the order they left, and of the recorded ones.
  const std::vector<KeyframePoseRecord>& Departed() const { return departed_; }
  std::vector<KeyframePoseRecord> Recorded() const;

 private:
  struct Keyframe {
    KeyframePoseRecord record;
    AffineBrightness brightness;  // relative to the oldest recorded keyframe's radiance
    std::shared_ptr<const ImagePyramid> pyramid;
    std::shared_ptr<const std::vector<WindowedBAPoint>> points;  // null before SetPoints
    std::vector<LineSegment> segments;
    std::vector<int> line_of_segment;  // segment index -> line id
  };
  struct Snapshot {
    std::map<int, SE3> world_from_kf;  // keyframe id -> at submission
    std::map<int, std::shared_ptr<const std::vector<WindowedBAPoint>>> points;
  };

  // The fraction of a keyframe's points in view of the newest keyframe (every few points);
  // -1 without points.
  double VisibleInNewest(const Keyframe& keyframe) const;

  PinholeCamera camera_;
  int size_;
  LeavingKeyframe leaving_;
  double min_visible_;
  std::deque<Keyframe> keyframes_;  // oldest first
  int next_line_id_ = 0;
  std::map<long, Snapshot> submitted_;
  // The prior the last applied result left (WindowedBAOptions::marginalize), given to the next
  // snapshots; null: none.
  std::shared_ptr<const WindowedBAPrior> prior_;
  std::vector<KeyframePoseRecord> departed_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_WINDOWED_BA_KEYFRAMES_H_
