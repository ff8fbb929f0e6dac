// Which keyframe leaves a full window (WindowedBAOptions::leaving; docs/windowed_ba.md, "What
// leaves the window"). `oldest` is a fixed lag. `spread` is DSO's keyframe marginalisation (Engel
// et al., PAMI 2018, Sec. 3.1 "Keyframe Marginalization"): a keyframe of which less than
// `min_visible` of the points is still in view of the newest keyframe leaves first (the oldest
// such); otherwise the one maximising the distance score
//   s(i) = sqrt(d(i, newest)) * sum_{j != i} 1 / (d(i, j) + eps),
// d the distance between camera centres: close to the other keyframes and far from the newest,
// so the window stays spread in space and keeps an old, distant keyframe for a long baseline.
// The score is invariant to the map's scale (eps scales with the distances).
#ifndef PLDVO_BACKEND_WINDOWED_BA_LEAVING_KEYFRAME_H_
#define PLDVO_BACKEND_WINDOWED_BA_LEAVING_KEYFRAME_H_

#include <Eigen/Core>
#include <vector>

#include "core/options.h"

namespace pldvo {

enum class LeavingKeyframe { kOldest, kSpread };
inline const ChoiceNames<LeavingKeyframe>& LeavingKeyframeNames() {
  static const ChoiceNames<LeavingKeyframe> names = {{"oldest", LeavingKeyframe::kOldest},
                                                     {"spread", LeavingKeyframe::kSpread}};
  return names;
}

// One keyframe of the window, oldest first.
struct LeavingCandidate {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // camera centre in the world
  // Fraction of its points in view of the newest keyframe; negative: unknown (never leaves by
  // visibility).
  double visible_in_newest = -1.0;
};

// The index of the keyframe that leaves, among all but the newest `protected_newest` (which
// never leave: the newest and the one whose final map is still to come). Requires
// keyframes.size() > protected_newest >= 1; throws std::invalid_argument otherwise.
int ChooseLeavingKeyframe(const std::vector<LeavingCandidate>& keyframes, LeavingKeyframe policy,
                          int protected_newest, double min_visible);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_LEAVING_KEYFRAME_H_
