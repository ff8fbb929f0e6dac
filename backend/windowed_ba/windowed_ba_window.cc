#include "backend/windowed_ba/windowed_ba_window.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace pldvo {
namespace {

[[noreturn]] void Throw(int line, const std::string& what) {
  throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(line) +
                              ": windowed BA window: " + what);
}

}  // namespace

void CheckWindowedBAWindow(const WindowedBAWindow& window) {
  const std::string camera_error = window.camera.Check();
  if (!camera_error.empty()) Throw(__LINE__, "camera: " + camera_error);
  if (window.keyframes.size() < 2) Throw(__LINE__, "fewer than 2 keyframes");
  if (!(window.intensity_noise_sigma >= 0.0) || !std::isfinite(window.intensity_noise_sigma)) {
    Throw(__LINE__, "intensity_noise_sigma must be >= 0 and finite");
  }
  for (size_t k = 0; k < window.keyframes.size(); ++k) {
    const WindowedBAKeyframe& keyframe = window.keyframes[k];
    const std::string name = "keyframe " + std::to_string(keyframe.id);
    if (k > 0 && keyframe.id <= window.keyframes[k - 1].id) {
      Throw(__LINE__, name + ": ids not strictly increasing");
    }
    if (keyframe.pyramid == nullptr || keyframe.pyramid->num_levels() < 1 ||
        keyframe.pyramid->width(0) != window.camera.width ||
        keyframe.pyramid->height(0) != window.camera.height) {
      Throw(__LINE__, name + ": missing pyramid or level 0 not the camera's size");
    }
    if (!keyframe.cam_from_world.translation().allFinite() ||
        !keyframe.cam_from_world.rotation_matrix().allFinite() ||
        !std::isfinite(keyframe.brightness.a) || !std::isfinite(keyframe.brightness.b)) {
      Throw(__LINE__, name + ": non-finite pose or brightness");
    }
    for (size_t i = 0; i < keyframe.points.size(); ++i) {
      const WindowedBAPoint& point = keyframe.points[i];
      if (!point.pixel.allFinite() || !(point.idepth > 0.0) || !std::isfinite(point.idepth) ||
          !(point.idepth_var > 0.0) || !std::isfinite(point.idepth_var)) {
        Throw(__LINE__, name + " point " + std::to_string(i) +
                            ": non-finite pixel or non-positive idepth / idepth_var");
      }
    }
    for (const WindowedBALineObservation& observation : keyframe.line_observations) {
      if (!observation.line_in_target.line.allFinite() ||
          std::abs(observation.line_in_target.line.head<2>().squaredNorm() - 1.0) > 1e-6) {
        Throw(__LINE__,
              name + " edge " + std::to_string(observation.edge_id) + ": line not normalised");
      }
    }
  }
  if (window.prior != nullptr) CheckWindowedBAPrior(*window.prior);
}

}  // namespace pldvo
