#include "backend/odometry/random_start_choice.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <stdexcept>
#include <vector>

#include "backend/odometry/loaded_frame.h"
#include "backend/odometry/odometry.h"
#include "core/wall_clock.h"

namespace pldvo {

RandomStartChoice ChooseRandomStart(const Dataset& dataset, const OdometryConfig& config,
                                    int num_frames, const CornerTracks* corners) {
  const int candidates = config.odometry.random_start_candidates;
  if (candidates < 2 || num_frames < 2) {
    throw std::invalid_argument(
        "ChooseRandomStart: needs random_start_candidates >= 2 and 2 frames");
  }
  const auto start = WallClock::now();
  RandomStartChoice choice;
  choice.frames = std::min(config.odometry.random_start_frames, num_frames);

  // The frames once for every candidate.
  std::vector<LoadedFrame> frames;
  for (int i = 0; i < choice.frames; ++i) frames.push_back(LoadFrame(dataset, i));

  // The corners one motion explains, once for every candidate.
  const CornerConsensus consensus =
      corners != nullptr ? FindCornerConsensus(*corners, dataset.camera(), choice.frames)
                         : CornerConsensus{};

  OdometryConfig base_config = config;
  base_config.odometry.parallel_mapping = false;
  base_config.odometry.compare_solver = OdometryOptions::CompareSolver::kNone;
  base_config.backend.edge_ba.enabled = false;
  base_config.backend.windowed_ba.enabled = false;
  // Candidate c's score (deterministic: the inline mapping).
  auto score = [&](int c) {
    RandomStartCandidate candidate;
    candidate.init_seed = config.mapping.init_seed + 1000 * c;
    OdometryConfig candidate_config = base_config;
    candidate_config.mapping.init_seed = candidate.init_seed;
    Odometry odometry(dataset.camera(), candidate_config);
    double correlation_sum = 0.0, rms_sum = 0.0;
    int tracked = 0;
    std::vector<SE3> world_from_cam;
    for (int i = 0; i < choice.frames; ++i) {
      const OdometryFrameResult result = ProcessOrSkip(dataset, i, frames[i], &odometry);
      world_from_cam.push_back(result.world_from_cam);
      if (i == 0) continue;  // the keyframe itself
      if (IsTracked(result.status)) {
        correlation_sum += result.tracking.intensity_correlation;
        rms_sum += result.tracking.final_rms;
        ++tracked;
      } else {
        ++candidate.untracked;
      }
    }
    odometry.Finish();
    if (corners != nullptr) {
      candidate.corner_error_px = CornerEpipolarErrorPx(consensus, world_from_cam);
    }
    if (tracked > 0) {
      candidate.mean_correlation = correlation_sum / tracked;
      candidate.mean_rms = rms_sum / tracked;
    }
    return candidate;
  };
  // Each candidate on its own thread; get() passes on what a candidate threw.
  std::vector<std::future<RandomStartCandidate>> scored;
  for (int c = 0; c < candidates; ++c) scored.push_back(std::async(std::launch::async, score, c));
  for (std::future<RandomStartCandidate>& candidate : scored) {
    choice.candidates.push_back(candidate.get());
  }
  choice.by_corners =
      config.odometry.random_start_corner_check &&
      std::all_of(choice.candidates.begin(), choice.candidates.end(),
                  [](const RandomStartCandidate& c) { return std::isfinite(c.corner_error_px); });
  const auto best =
      std::min_element(choice.candidates.begin(), choice.candidates.end(),
                       [&](const RandomStartCandidate& a, const RandomStartCandidate& b) {
                         if (a.untracked != b.untracked) return a.untracked < b.untracked;
                         return choice.by_corners ? a.corner_error_px < b.corner_error_px
                                                  : a.mean_correlation > b.mean_correlation;
                       });
  choice.init_seed = best->init_seed;
  choice.ms = MsSince(start);
  return choice;
}

}  // namespace pldvo
