// The frames before a re-anchored two-view start (odometry.two_view_max_anchor; docs/bootstrap.md,
// "Re-anchored two-view start"). Where frame 0's corners are lost before they fix a second view,
// the two-view start can begin at the frame where they were lost (the anchor a) and the run goes
// on from a's map; frames 0 .. a - 1 are tracked backwards from that same map, a, a - 1, ..., 0,
// by an odometry of their own, so the whole sequence is one trajectory in one scale.
#ifndef PLDVO_BACKEND_ODOMETRY_BACKWARD_START_H_
#define PLDVO_BACKEND_ODOMETRY_BACKWARD_START_H_

#include <opencv2/core.hpp>
#include <vector>

#include "backend/odometry/odometry.h"
#include "backend/odometry/odometry_config.h"
#include "core/dataset.h"
#include "core/trajectory_io.h"

namespace pldvo {

struct BackwardStart {
  // The tracked frames among 0 .. anchor - 1, by the dataset's timestamps in increasing order;
  // world_from_cam with the anchor's camera as the world (the run from the anchor's).
  Trajectory poses;
  OdometryStatistics statistics;  // over the anchor and the frames before it
  double ms = 0.0;                // wall time
};

// Runs `run_config` (without edge or windowed BA and the solver comparison, mapping inline) over
// frames anchor, anchor - 1, ..., 0 of `dataset` (timestamps mirrored about the anchor's,
// core/frame_range_view.h), the anchor starting from `anchor_depth` (z-depth, 0 where none) with
// odometry.init_depth_idepth_var. A frame that cannot be loaded or processed is skipped, as in
// the run. Throws std::invalid_argument when anchor is not a frame of the dataset or < 1.
BackwardStart TrackBackwardFromAnchor(const Dataset& dataset, const OdometryConfig& run_config,
                                      int anchor, const cv::Mat& anchor_depth);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_BACKWARD_START_H_
