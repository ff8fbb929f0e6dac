// What a window leaves behind when keyframes leave it (docs/windowed_ba.md, "What leaves the
// window"): a Gaussian prior on the poses of the keyframes that stay, in information form,
// linearised at their poses when it was made. DSO keeps the same (Engel et al. PAMI 2018,
// Sec. 3.2) over poses, brightness and camera; here it is over the poses only (the brightness
// inputs are re-chained from tracking for every window, so a prior on them would refer to
// another gauge).
//
//   E(d) = 1/2 d^T H d + b^T d,   d_k = Minus(T_k, T0_k) = Log(T_k T0_k^-1)   (T = cam_from_world)
//
// Made by MarginalizeOldestKeyframe (marginalization.h), given to the next window in
// WindowedBAWindow::prior, added to its problem as a PosePriorResidual.
#ifndef PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_PRIOR_H_
#define PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_PRIOR_H_

#include <Eigen/Core>
#include <vector>

#include "core/se3.h"

namespace pldvo {

struct WindowedBAPrior {
  // Keyframes with an id up to this one have been marginalised into the prior: a window that
  // still holds one of them must not use it (their rows would count twice).
  int marginalized_through_id = -1;
  std::vector<int> keyframe_ids;    // strictly increasing
  std::vector<SE3> cam_from_world;  // T0, one per id
  Eigen::MatrixXd information;      // H, 6K x 6K
  Eigen::VectorXd gradient;         // b, 6K
};

// Throws std::invalid_argument when the sizes disagree, the ids do not increase or are not
// above marginalized_through_id, or an entry is not finite.
void CheckWindowedBAPrior(const WindowedBAPrior& prior);

// Marginalises the variables whose `keep` entry is false (Schur complement): H' = H_kk -
// H_km H_mm^+ H_mk, b' = b_k - H_km H_mm^+ b_m, with H_mm^+ the pseudo-inverse over its
// eigenvalues above 1e-12 of the largest (a gauge direction of the eliminated block adds
// nothing). `keep` has one entry per row of `information`.
void SchurComplement(const Eigen::MatrixXd& information, const Eigen::VectorXd& gradient,
                     const std::vector<bool>& keep, Eigen::MatrixXd* kept_information,
                     Eigen::VectorXd* kept_gradient);

// The prior on the subset of its keyframes listed in `keep_ids` (others marginalised out).
// Returns false when none of them is kept.
bool KeepKeyframes(const WindowedBAPrior& prior, const std::vector<int>& keep_ids,
                   WindowedBAPrior* kept);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_PRIOR_H_
