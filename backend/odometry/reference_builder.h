// Turns a keyframe's semi-dense inverse-depth map (backend/mapping/semi_dense_depth_map.h, level 0)
// and the current frame's line matches into the TrackingReference the tracker aligns the frame to
// (seed paper Sec. IV; LSD-SLAM's TrackingReference::makePointCloud).
//
// Points per level: level 0 has one point per valid hypothesis with idepth >= 0. A level-l point
// aggregates the valid level-0 hypotheses of its 2^l x 2^l block (pyramid convention of
// tracking_reference.h, block [2^l x, 2^l (x + 1)) x [2^l y, 2^l (y + 1))) by inverse-variance
// weighting:
//   idepth_l = sum_i idepth_i / V_i / sum_i 1 / V_i,    V_l = n / sum_i 1 / V_i,
// i.e. the variance is the harmonic mean of the block's variances, not divided by n: the
// hypotheses of neighbouring pixels are correlated (regularisation, shared stereo patches), so
// averaging them does not make the inverse depth n times more certain. The intensity is the
// level-l keyframe pyramid at the level pixel; the edge id is that of the block's edge pixel
// with the largest 1 / V (none when the block has no edge pixel).
//
// Budget: with max_points_per_level > 0 a level with n > max points keeps the points of raster
// index floor(k n / max), k = 0..max-1: evenly spaced, so the subset covers the image like the
// full set (a stride of n / max). Tracking time is linear in the points; the semi-dense map
// itself is not thinned.
//
// Lines: the current-frame segment matched to keyframe edge e (LineMatch, ref_index = e) gives
// MatchedLine e at level 0 (the segment's l and Sigma_l); LineAtLevel moves it to each level.
#ifndef PLDVO_BACKEND_ODOMETRY_REFERENCE_BUILDER_H_
#define PLDVO_BACKEND_ODOMETRY_REFERENCE_BUILDER_H_

#include <vector>

#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/tracking/tracking_reference.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "frontend/line_matcher.h"
#include "frontend/line_segment.h"

namespace pldvo {

// The points of every level (levels = keyframe.num_levels()), at most max_points_per_level each
// (0 = all); lines_in_cur left empty. `keyframe` is the keyframe's pyramid, `camera` its level-0
// camera; throws std::invalid_argument when the map, pyramid and camera sizes differ.
// `keyframe_lines[e]` is the level-0 keyframe line l = (a, b, c), a^2 + b^2 = 1, of edge id e
// (zero or missing: unknown); an edge point's pixel_on_edge is its foot point on that line.
TrackingReference BuildReferencePoints(const SemiDenseDepthMap& map, const ImagePyramid& keyframe,
                                       const PinholeCamera& camera, int max_points_per_level = 0,
                                       const std::vector<Eigen::Vector3d>& keyframe_lines = {});

// Level-0 matched lines indexed by keyframe edge id (= keyframe segment index): entry
// match.ref_index holds cur_segments[match.cur_index]; entries without a match are unmatched.
std::vector<MatchedLine> MatchedLinesFromMatches(const std::vector<LineMatch>& matches,
                                                 const std::vector<LineSegment>& cur_segments,
                                                 int num_keyframe_segments);

// Sets lines_in_cur of every level of `reference` from the level-0 lines (LineAtLevel).
void SetMatchedLines(const std::vector<MatchedLine>& lines_at_level0, TrackingReference* reference);

// Verifies the matched lines at a pose: for every matched edge of level 0, the median distance
// |l^T x'| of its points reprojected with cur_from_ref; edges above max_median_px are unmatched
// in every level of `reference` and in `lines_at_level0` (may be null). Returns how many.
int RemoveLineOutliers(const SE3& cur_from_ref, double max_median_px, TrackingReference* reference,
                       std::vector<MatchedLine>* lines_at_level0);

// Fraction of the reference points of `level` that reproject inside the current image with
// cur_from_ref (1 when the level has no points).
double ReferenceOverlap(const TrackingReference& reference, int level, const SE3& cur_from_ref);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_REFERENCE_BUILDER_H_
