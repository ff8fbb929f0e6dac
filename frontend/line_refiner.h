// Sub-pixel refit of detected segments to the image's edge (docs/line_frontend.md, "Sub-pixel
// refit"). The current segment's detection error is most of the line-guided stereo's error
// (docs/mapping.md, "The current segment's detection error"), and the detectors place a segment
// from integer edge pixels. For each segment, every sample_step_px along it (not within
// sample_step_px of an endpoint), the directional derivative across it,
//   g(s) = I(p + (s + 1/2) n) - I(p + (s - 1/2) n),   s = -search_radius_px .. search_radius_px,
// (bilinear samples, n the segment's unit normal) is searched for its maximum with the
// segment's polarity (the sign of the summed g(0)); an interior maximum of at least
// min_edge_step gray levels gives the edge point p + (s* + delta) n, delta the centroid of
// g(s* - 1), g(s*), g(s* + 1) (clipped at 0) about s*. cv::fitLine (least squares) fits the line to
// these points and the endpoints are projected onto it; up to three passes, until the endpoints
// move less than 0.01 px. The segment keeps its extent, direction and octave and gets Sigma_l
// anew. The refit is refused, and the segment kept, when a pass finds fewer than
// min_point_fraction of its samples' edge points, or when the refit turns the segment by more
// than max_angle_deg or moves its midpoint by more than max_shift_px.
#ifndef PLDVO_FRONTEND_LINE_REFINER_H_
#define PLDVO_FRONTEND_LINE_REFINER_H_

#include <opencv2/core.hpp>
#include <vector>

#include "frontend/line_frontend_options.h"
#include "frontend/line_segment.h"

namespace pldvo {

// Refits `segments` (full-resolution pixels) in place on `gray` (CV_8U, full resolution); the
// new Sigma_l has endpoint standard deviation endpoint_sigma_px * 2^octave. Returns how many
// were refitted. Throws std::invalid_argument unless gray is CV_8U.
int RefineSegmentsToEdges(const cv::Mat& gray, const LineRefinerOptions& options,
                          double endpoint_sigma_px, std::vector<LineSegment>* segments);

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_REFINER_H_
