// Merging of broken segments. Detectors split one image edge into several collinear pieces
// (noise, low contrast, crossings) and the two detection octaves report most edges twice. The
// merger indexes the segments in a bucket grid (midpoint cell x directed orientation bin),
// greedily grows the longest unmerged segment by every segment in the buckets along it that
//   - points the same way within max_angle_deg (directed: polarity must agree),
//   - has both endpoints within max_line_distance_px of the growing segment's line, and
//   - leaves a gap of at most max_gap_px along that line (overlap counts as gap 0),
// and repeats until nothing more joins. The merged line passes through the weighted centroid
// of the parts' midpoints along their weighted mean direction (weight = length / 4^octave, an
// inverse-variance weight: octave-k endpoints are 2^k times noisier), and spans the extreme
// projections of all parts' endpoints. Finally segments shorter than min_length_px are dropped.
#ifndef PLDVO_FRONTEND_LINE_MERGER_H_
#define PLDVO_FRONTEND_LINE_MERGER_H_

#include <vector>

#include "frontend/line_frontend_options.h"
#include "frontend/line_segment.h"

namespace pldvo {

class LineMerger {
 public:
  // `endpoint_sigma_px` (octave 0) sets Sigma_l of the merged segments as in LineDetector.
  // Throws std::invalid_argument when options.Check() fails.
  LineMerger(const LineMergerOptions& options, double endpoint_sigma_px);

  // The merged segments, longest first, each at least min_length_px long.
  std::vector<LineSegment> Merge(const std::vector<LineSegment>& segments) const;

 private:
  LineMergerOptions options_;
  double endpoint_sigma_px_;
};

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_MERGER_H_
