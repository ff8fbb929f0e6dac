#include "backend/windowed_ba/leaving_keyframe.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pldvo {

int ChooseLeavingKeyframe(const std::vector<LeavingCandidate>& keyframes, LeavingKeyframe policy,
                          int protected_newest, double min_visible) {
  const int n = static_cast<int>(keyframes.size());
  if (protected_newest < 1 || n <= protected_newest) {
    throw std::invalid_argument("ChooseLeavingKeyframe: needs more keyframes than protected ones");
  }
  if (policy == LeavingKeyframe::kOldest) return 0;
  const int candidates = n - protected_newest;
  for (int i = 0; i < candidates; ++i) {
    const double visible = keyframes[i].visible_in_newest;
    if (visible >= 0.0 && visible < min_visible) return i;
  }
  // eps: DSO's 1e-5 relative to the window's largest distance, so the choice does not depend on
  // the map's scale; coincident keyframes (pure rotation) then score highest and leave first.
  double largest = 0.0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      largest = std::max(largest, (keyframes[i].centre - keyframes[j].centre).norm());
    }
  }
  if (!(largest > 0.0) || !std::isfinite(largest)) return 0;
  const double eps = 1e-5 * largest;
  const Eigen::Vector3d& newest = keyframes.back().centre;
  int leaving = 0;
  double best = -1.0;
  for (int i = 0; i < candidates; ++i) {
    double inverse_distances = 0.0;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      inverse_distances += 1.0 / ((keyframes[i].centre - keyframes[j].centre).norm() + eps);
    }
    const double score = std::sqrt((keyframes[i].centre - newest).norm()) * inverse_distances;
    if (score > best) {
      best = score;
      leaving = i;
    }
  }
  return leaving;
}

}  // namespace pldvo
