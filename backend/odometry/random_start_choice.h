// Best of several random starts (odometry.random_start_candidates; docs/bootstrap.md, "Best of
// several random starts").
//
// A monocular run without a two-view start tracks its first frames against a random
// inverse-depth map (Engel et al. 2013, Sec. 2.1), and which self-consistent pair of map and
// motion those frames settle into depends on the random values: on the texture-less rooms, 8
// initial maps of one sequence end 0.3-12 cm/s apart. Here the start runs from several initial
// maps over the first frames, and the run starts from the one whose frames fit their keyframes
// best: fewest frames not tracked, then the highest mean intensity correlation between the
// keyframe's points and the frame at the tracked pose. The correlation does not change with the
// image's contrast or with the image noise; the final RMS is whitened by the noise that the
// previous frame's residuals imply, which grows with a wrong start's misfit, and tells it less
// well (docs/bootstrap.md). A wrong start fits the first keyframe's own frames as well as a right
// one; it shows once the frames are tracked against the keyframes built from it. Where frame 0's
// corners fix the translation direction roughly (the two-view start failed only at its direction
// gate), they decide instead of the correlation: the lowest epipolar error of the tracked corners
// against the candidate's poses (corner_epipolar_error.h).
#ifndef PLDVO_BACKEND_ODOMETRY_RANDOM_START_CHOICE_H_
#define PLDVO_BACKEND_ODOMETRY_RANDOM_START_CHOICE_H_

#include <limits>
#include <vector>

#include "backend/odometry/corner_epipolar_error.h"
#include "backend/odometry/odometry_config.h"
#include "core/dataset.h"

namespace pldvo {

struct RandomStartCandidate {
  int init_seed = 0;  // mapping.init_seed of its initial map
  int untracked = 0;  // frames 1.. not tracked (lost, re-initialised or failed)
  // Over the tracked frames 1..: TrackingResult::intensity_correlation (the score) and final_rms
  // (reported); 0 when none.
  double mean_correlation = 0.0;
  double mean_rms = 0.0;
  // CornerEpipolarErrorPx of the corners against frames 0..; NaN without corners.
  double corner_error_px = std::numeric_limits<double>::quiet_NaN();
};

struct RandomStartChoice {
  int init_seed = 0;        // the chosen candidate's
  bool by_corners = false;  // chosen by corner_error_px (else by mean_correlation)
  std::vector<RandomStartCandidate> candidates;
  int frames = 0;   // frames each candidate ran
  double ms = 0.0;  // wall time of all candidates
};

// Candidate c (0 .. random_start_candidates - 1) starts from mapping.init_seed + 1000 c; each
// runs `config` over the first min(random_start_frames, num_frames) frames of `dataset` with the
// mapping inline (the run's results with its mapping thread, odometry.mapping_lag), without edge
// or windowed BA and the solver comparison, each on its own thread (the scores do not depend on
// it). The images are loaded once; a frame that cannot be loaded is
// skipped as in the run. The best has the fewest untracked frames, then, with `corners` (the
// two-view start's unsettled tracks) and odometry.random_start_corner_check, the lowest
// corner_error_px, otherwise the highest mean_correlation; ties go to the lower candidate. Throws
// std::invalid_argument when random_start_candidates < 2 or num_frames < 2.
RandomStartChoice ChooseRandomStart(const Dataset& dataset, const OdometryConfig& config,
                                    int num_frames, const CornerTracks* corners = nullptr);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_RANDOM_START_CHOICE_H_
