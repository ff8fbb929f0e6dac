// Which semi-dense points of a keyframe enter windowed bundle adjustment (docs/windowed_ba.md):
// a sparse, well-spread subset, as DSO selects ~2000 points per window. The image is divided into
// square cells sized so that there are about `budget` of them (side sqrt(w h / budget), at least
// 1 px); in each cell the candidate with the largest image gradient wins, provided its gradient
// is at least `min_gradient` and its pattern (`pattern_radius` px around it) lies inside the
// sampling area [1, w - 2) x [1, h - 2); the winners are then kept in order of decreasing
// gradient up to `budget`. Spreading matters because the window's poses are constrained by
// points all over the image; the gradient because a point's photometric rows constrain its
// inverse depth and the poses in proportion to it (eq. 5 weights by the same gradient).
#ifndef PLDVO_BACKEND_WINDOWED_BA_POINT_SELECTION_H_
#define PLDVO_BACKEND_WINDOWED_BA_POINT_SELECTION_H_

#include <vector>

#include "backend/windowed_ba/windowed_ba_window.h"
#include "core/image_pyramid.h"

namespace pldvo {

// Indices into `points` of the selected ones, in decreasing gradient (ties: lower index first).
// Deterministic. budget <= 0 selects none.
std::vector<int> SelectWindowPoints(const std::vector<WindowedBAPoint>& points,
                                    const ImagePyramid& pyramid, int budget, double min_gradient,
                                    double pattern_radius);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_POINT_SELECTION_H_
