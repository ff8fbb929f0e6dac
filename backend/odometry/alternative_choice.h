// Which of a frame's tracking results wins when the odometry retries it from alternative initial
// guesses (odometry.try_alternatives, odometry.alternative_choice; docs/odometry.md).
#ifndef PLDVO_BACKEND_ODOMETRY_ALTERNATIVE_CHOICE_H_
#define PLDVO_BACKEND_ODOMETRY_ALTERNATIVE_CHOICE_H_

#include "backend/odometry/odometry_config.h"
#include "backend/tracking/tracker.h"

namespace pldvo {

// The score of a result at the finest level: its inlier rows, or with kCorrelatedInlierRows its
// inlier rows times the intensity correlation of its photometric rows (clamped at 0; without
// photometric rows, lines only, the inlier rows). Not the lower RMS: a wrong pose that pushes
// points out of the image or onto flat regions can have fewer valid rows and a lower RMS.
double AlternativeScore(const TrackingResult& result, OdometryOptions::AlternativeChoice choice);

// Whether `a` beats `b`: not lost beats lost, then the higher AlternativeScore; with
// kRowsAndCorrelation, more inlier rows and (where both have photometric rows) an intensity
// correlation no lower, so an alternative replaces the first result only where it is better in
// both.
bool BetterAlternative(const TrackingResult& a, const TrackingResult& b,
                       OdometryOptions::AlternativeChoice choice);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_ALTERNATIVE_CHOICE_H_
