// The regularisation steps of the semi-dense filter (Engel, Sturm, Cremers, ICCV 2013,
// Sec. 2.3), on a (2r+1)^2 window, r = options.regularization_radius:
//  - smoothing: each valid inverse depth becomes the inverse-variance weighted mean of itself
//    and the valid neighbours j with (D_i - D_j)^2 <= g^2 (V_i + V_j), g =
//    regularization_gate_sigmas (neighbours across a depth discontinuity do not interact).
//    The variance is left unchanged: the neighbours' errors are correlated (they come from
//    overlapping SSD patches), so 1 / sum(1 / V_j) would be overconfident;
//  - outlier removal: a hypothesis with fewer than min_neighbors_keep compatible valid
//    neighbours is dropped (isolated, hence likely a wrong match);
//  - hole filling: an invalid, non-blacklisted candidate with at least min_neighbors_fill valid
//    neighbours gets their inverse-variance weighted mean with the initial variance
//    init_idepth_var, so that the next frame's stereo searches it.
#ifndef PLDVO_BACKEND_MAPPING_DEPTH_REGULARIZER_H_
#define PLDVO_BACKEND_MAPPING_DEPTH_REGULARIZER_H_

#include "backend/mapping/mapping_options.h"
#include "backend/mapping/semi_dense_depth_map.h"

namespace pldvo {

// Writes `in` with smoothed means into *out (out may not alias in). Returns the number of
// hypotheses that had at least one compatible neighbour.
int SmoothDepthMap(const SemiDenseDepthMap& in, const MappingOptions& options,
                   SemiDenseDepthMap* out);
// Returns the number of hypotheses removed.
int RemoveIsolatedHypotheses(const MappingOptions& options, SemiDenseDepthMap* map);
// Returns the number of holes filled.
int FillHoles(const MappingOptions& options, SemiDenseDepthMap* map);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_DEPTH_REGULARIZER_H_
