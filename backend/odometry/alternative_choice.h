// Which of a frame's tracking results wins when the odometry retries it from alternative initial
// guesses (odometry.try_alternatives, odometry.alternative_choice; docs/odometry.md).
#ifndef PLDVO_BACKEND_ODOMETRY_ALTERNATIVE_CHOICE_H_
#define PLDVO_BACKEND_ODOMETRY_ALTERNATIVE_CHOICE_H_

#include "backend/odometry/odometry_config.h"
#include "backend/tracking/tracker.h"
#include "core/se3.h"

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

// A motion's size in image angle at the mean scene depth: rotation angle + |t| * mean_idepth
// (radians; the translation's parallax, as keyframes.max_relative_distance measures it).
double ImageMotion(const SE3& motion, double mean_idepth);

// Whether `alternative` ends further from `first` than the constant-velocity prior moves the
// camera over the frame (`prior_step`: the prior's cur_from_last_good), in ImageMotion: it then
// claims that the motion changed by more than the whole motion in one frame.
bool BeyondPriorStep(const TrackingResult& alternative, const TrackingResult& first,
                     const SE3& prior_step, double mean_idepth);

// Whether `alternative` may compete with the first result at all. With kMotionGatedInlierRows an
// alternative beyond the prior's step (BeyondPriorStep) competes only when the first result is
// lost or the alternative's intensity correlation is no lower than the first's: the neighbouring
// period of a repetitive pattern gains inlier rows, not correlation, while an alternative that
// ends near the first result (a better-converged solve of the same minimum) competes by its
// inlier rows. Every other choice: always.
bool AlternativeMayCompete(const TrackingResult& alternative, const TrackingResult& first,
                           const SE3& prior_step, double mean_idepth,
                           OdometryOptions::AlternativeChoice choice);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_ALTERNATIVE_CHOICE_H_
