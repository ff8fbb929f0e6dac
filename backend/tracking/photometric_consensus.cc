#include "backend/tracking/photometric_consensus.h"

#include <stdexcept>
#include <string>
#include <utility>

namespace pldvo {

TrackingOptions PhotometricConsensus::FinestPhotometric(TrackingOptions tracking) {
  tracking.problem.weighting.policy = WeightingPolicy::kPhotometricOnly;
  tracking.coarsest_level = tracking.finest_level;
  tracking.pose_covariance = false;
  return tracking;
}

PhotometricConsensus::PhotometricConsensus(const TrackingOptions& tracking, double max_cost_drop)
    : tracker_(FinestPhotometric(tracking)), max_cost_drop_(max_cost_drop) {
  if (!(max_cost_drop > 0.0)) {
    throw std::invalid_argument("PhotometricConsensus: max_cost_drop must be > 0, got " +
                                std::to_string(max_cost_drop));
  }
}

std::optional<TrackingResult> PhotometricConsensus::Check(const TrackingReference& reference,
                                                          const ImagePyramid& current,
                                                          const TrackingResult& joint) const {
  TrackingResult photometric =
      tracker_.Track(reference, current, joint.cur_from_ref, joint.brightness);
  if (photometric.status == TrackingStatus::kLost || photometric.levels.empty()) {
    return std::nullopt;
  }
  const LevelResult& finest = photometric.levels.back();
  if (!(finest.initial_cost - finest.final_cost > max_cost_drop_)) return std::nullopt;
  photometric.initial_cur_from_ref = joint.initial_cur_from_ref;
  return photometric;
}

}  // namespace pldvo
