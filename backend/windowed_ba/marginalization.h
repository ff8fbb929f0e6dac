// Marginalising the keyframe that leaves a window (docs/windowed_ba.md, "What leaves the
// window"), as DSO does (Engel et al. PAMI 2018, Sec. 3.2): after a window is solved, the rows
// that will not be in the next window, the points hosted in its oldest keyframe (photometric
// and point-to-line rows, inverse-depth priors) and the window's own prior, are linearised at
// the solution; their inverse depths and the oldest pose are eliminated by Schur complement,
// leaving a WindowedBAPrior on the other poses. The brightness is held at the solution (the
// prior is on poses only), and rows of other hosts' points into the oldest keyframe are
// dropped, as DSO drops them.
#ifndef PLDVO_BACKEND_WINDOWED_BA_MARGINALIZATION_H_
#define PLDVO_BACKEND_WINDOWED_BA_MARGINALIZATION_H_

#include <vector>

#include "backend/windowed_ba/windowed_ba_prior.h"
#include "backend/windowed_ba/windowed_ba_problem_builder.h"

namespace pldvo {

// `keyframe_ids`: the ids of the problem's window positions, oldest first. Changes which of the
// problem's parameter blocks are constant (it is done with). Returns false when the window has
// fewer than two keyframes or the rows do not evaluate.
bool MarginalizeOldestKeyframe(const std::vector<int>& keyframe_ids, WindowedBAProblem* problem,
                               WindowedBAPrior* prior);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_MARGINALIZATION_H_
