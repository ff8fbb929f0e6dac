// The photometric consensus check on a frame's line term (odometry.line_consensus_max_cost_drop;
// issue: lines must fail safe on repetitive patterns and occlusion edges). After tracking with
// points and lines, a photometric-only solve at the finest level starts from the result, on the
// problem built at the result's pose. Its cost drop, initial - final (0.5 sum of the whitened,
// robust photometric rows), measures how far the line term pulled the pose against the
// photometric evidence: a direction the image leaves free (texture-less) costs nothing, a wrong
// match that drags the pose across textured pixels costs more than chi^2 allows.
#ifndef PLDVO_BACKEND_TRACKING_PHOTOMETRIC_CONSENSUS_H_
#define PLDVO_BACKEND_TRACKING_PHOTOMETRIC_CONSENSUS_H_

#include <optional>

#include "backend/tracking/tracker.h"

namespace pldvo {

class PhotometricConsensus {
 public:
  // `tracking`: the odometry's tracking options (solver, weighting, levels); the check solves
  // their finest level with the photometric rows only. Throws std::invalid_argument for
  // max_cost_drop <= 0 or invalid options.
  PhotometricConsensus(const TrackingOptions& tracking, double max_cost_drop);

  // The photometric-only result when the photometric cost drops by more than max_cost_drop from
  // `joint` (the line term disagrees); nullopt when it does not or that solve is lost.
  std::optional<TrackingResult> Check(const TrackingReference& reference,
                                      const ImagePyramid& current,
                                      const TrackingResult& joint) const;

 private:
  static TrackingOptions FinestPhotometric(TrackingOptions tracking);

  Tracker tracker_;
  double max_cost_drop_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_TRACKING_PHOTOMETRIC_CONSENSUS_H_
