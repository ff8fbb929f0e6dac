#include "backend/edge_ba/edge_ba_options.h"

#include <cmath>

namespace pldvo {

std::string EdgeBAOptions::Check() const {
  if (window < 2) return "backend.edge_ba.window must be >= 2";
  if (max_iterations < 1) return "backend.edge_ba.max_iterations must be >= 1";
  if (!(function_tolerance > 0.0)) return "backend.edge_ba.function_tolerance must be > 0";
  if (!(robust_threshold > 0.0) || !std::isfinite(robust_threshold)) {
    return "backend.edge_ba.robust_threshold must be positive and finite";
  }
  if (!(default_sigma_px > 0.0) || !std::isfinite(default_sigma_px)) {
    return "backend.edge_ba.default_sigma_px must be positive and finite";
  }
  if (max_pixels_per_observation < 0 || max_pixels_per_observation == 1) {
    return "backend.edge_ba.max_pixels_per_observation must be 0 or >= 2";
  }
  if (!(baseline_prior_sigma_ratio > 0.0) || !std::isfinite(baseline_prior_sigma_ratio)) {
    return "backend.edge_ba.baseline_prior_sigma_ratio must be positive and finite";
  }
  if (min_observing_keyframes < 2) return "backend.edge_ba.min_observing_keyframes must be >= 2";
  if (!(min_plane_angle_deg >= 0.0) || !(min_plane_angle_deg < 90.0)) {
    return "backend.edge_ba.min_plane_angle_deg must be in [0, 90)";
  }
  if (!(motion_prior_translation_ratio > 0.0) || !std::isfinite(motion_prior_translation_ratio)) {
    return "backend.edge_ba.motion_prior_translation_ratio must be positive and finite";
  }
  if (!(motion_prior_rotation_deg > 0.0) || !std::isfinite(motion_prior_rotation_deg)) {
    return "backend.edge_ba.motion_prior_rotation_deg must be positive and finite";
  }
  if (num_threads < 1) return "backend.edge_ba.num_threads must be >= 1";
  if (max_queue < 1) return "backend.edge_ba.max_queue must be >= 1";
  return "";
}

}  // namespace pldvo
