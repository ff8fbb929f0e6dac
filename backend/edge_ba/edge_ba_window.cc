#include "backend/edge_ba/edge_ba_window.h"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace pldvo {
namespace {

[[noreturn]] void ThrowInvalid(int line, const std::string& what) {
  std::ostringstream message;
  message << __FILE__ << ":" << line << ": EdgeBAWindow: " << what;
  throw std::invalid_argument(message.str());
}

}  // namespace

void CheckEdgeBAWindow(const EdgeBAWindow& window) {
  const std::string camera_error = window.camera.Check();
  if (!camera_error.empty()) ThrowInvalid(__LINE__, "camera: " + camera_error);
  for (size_t k = 0; k < window.keyframes.size(); ++k) {
    const EdgeBAKeyframe& keyframe = window.keyframes[k];
    const std::string where = "keyframe " + std::to_string(keyframe.id);
    if (k > 0 && !(keyframe.id > window.keyframes[k - 1].id)) {
      ThrowInvalid(__LINE__, where + ": ids must increase strictly (oldest first)");
    }
    if (!keyframe.cam_from_world.translation().allFinite() ||
        !keyframe.cam_from_world.rotation().coeffs().allFinite()) {
      ThrowInvalid(__LINE__, where + ": non-finite pose");
    }
    for (size_t i = 0; i < keyframe.observations.size(); ++i) {
      const EdgeBAObservation& observation = keyframe.observations[i];
      const std::string obs = where + " observation " + std::to_string(i);
      if (observation.line_id < 0) ThrowInvalid(__LINE__, obs + ": negative line_id");
      if (observation.pixels.empty()) ThrowInvalid(__LINE__, obs + ": no pixels");
      for (const Eigen::Vector2d& pixel : observation.pixels) {
        if (!pixel.allFinite()) ThrowInvalid(__LINE__, obs + ": non-finite pixel");
      }
      if (!std::isfinite(observation.sigma_px)) {
        ThrowInvalid(__LINE__, obs + ": non-finite sigma_px");
      }
    }
  }
  std::set<int> ids;
  for (const EdgeBALine& line : window.lines) {
    const std::string where = "line " + std::to_string(line.id);
    if (line.id < 0) ThrowInvalid(__LINE__, where + ": negative id");
    if (!ids.insert(line.id).second) ThrowInvalid(__LINE__, where + ": duplicate id");
    if (!line.point_in_world.allFinite() || !line.direction_in_world.allFinite() ||
        !(line.direction_in_world.norm() > 0.0)) {
      ThrowInvalid(__LINE__, where + ": non-finite point or zero direction");
    }
  }
}

}  // namespace pldvo
