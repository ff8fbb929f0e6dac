// Alternating refinement of the monocular bootstrap (odometry.bootstrap_passes; docs/odometry.md,
// "Bootstrap refinement").
//
// A monocular run starts from a random inverse-depth map (Engel 2013 Sec. 2.1): the first frames
// are tracked against it, and the first keyframe's map is then estimated by stereo from those
// poses. When that map ends up distorted, every later keyframe inherits it. A pass here runs the
// odometry over the first keyframe's frames (until the second keyframe starts) and keeps the
// first keyframe's final map; the next pass starts from that map instead of the random one,
// re-tracks the same frames against it and re-estimates it from the new poses. Each pass is one
// step of an alternation between the poses and the map; the run proper then starts from the last
// pass's map. The passes write nothing; only their time and size are reported.
#ifndef PLDVO_BACKEND_ODOMETRY_BOOTSTRAP_REFINER_H_
#define PLDVO_BACKEND_ODOMETRY_BOOTSTRAP_REFINER_H_

#include <opencv2/core.hpp>
#include <vector>

#include "backend/odometry/odometry_config.h"
#include "core/dataset.h"

namespace pldvo {

struct BootstrapRefinement {
  // Frame 0's z-depth (CV_32F; 0 where the map has no observed hypothesis), scaled so that the
  // median inverse depth is 1: the start of the run proper, with odometry.bootstrap_idepth_var.
  cv::Mat depth;
  // Per pass (odometry.bootstrap_passes - 1 of them): frames processed and observed hypotheses of
  // the first keyframe's final map.
  std::vector<int> frames;
  std::vector<int> points;
  double ms = 0.0;  // wall time of all passes
};

// Runs config.odometry.bootstrap_passes - 1 passes over the first frames of `dataset` (at most
// `num_frames`); frames that cannot be loaded are skipped as in the run. The passes use `config`
// without edge BA and the solver comparison. Throws std::invalid_argument when the config asks
// for no refinement (bootstrap_passes < 2) and std::runtime_error when a pass ends without any
// observed hypothesis.
BootstrapRefinement RefineBootstrap(const Dataset& dataset, const OdometryConfig& config,
                                    int num_frames);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_BOOTSTRAP_REFINER_H_
