// Ground truth that starts on a straight line at one constant speed (docs/evaluation.md,
// "Extrapolated ground truth").
//
// A measured trajectory (motion capture, GPS/INS, a rendered hand-held path) changes its velocity
// from pose to pose: vibration, noise and steering, by more than 1e-3 of the speed on 99% of the
// steps of the development set's other sequences. KITTI 00's first 14 poses do not: their
// velocities (world frame) agree to 2e-5 of the speed and they turn by the same 0.139 deg per
// frame; two independent estimators (the two-view corner adjustment, and tracking against a map
// built from the ground truth's own poses) find the car accelerating there. Such a start was filled
// in, not measured, and evaluating an estimate against it measures the filling.
#ifndef PLDVO_CORE_CONSTANT_VELOCITY_START_H_
#define PLDVO_CORE_CONSTANT_VELOCITY_START_H_

#include "core/trajectory_io.h"

namespace pldvo {

// The number of leading poses of `trajectory` that move at one constant velocity: the largest n
// such that the velocities v_i = (p_i - p_(i-1)) / (t_i - t_(i-1)), i = 1..n-1, each differ from
// the previous one by at most relative_tolerance |v_(i-1)|. 0 unless that prefix has at least
// min_steps velocities, or when the first speed is below 1e-6 m/s (a camera at rest). Throws
// std::invalid_argument for a negative tolerance, min_steps < 1 or non-increasing timestamps.
// The default min_steps: a measured path may repeat its velocity for a step or two by chance, not
// for five (KITTI 00's start has 13 steps; elsewhere on the development set no run of steps
// within 1e-3 is longer than 2).
int ConstantVelocityStartPoses(const Trajectory& trajectory, double relative_tolerance,
                               int min_steps = 5);

}  // namespace pldvo

#endif  // PLDVO_CORE_CONSTANT_VELOCITY_START_H_
