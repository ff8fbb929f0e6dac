#include "backend/odometry/odometry_config.h"

#include <cmath>

namespace pldvo {

std::string KeyframeOptions::Check() const {
  if (!(max_relative_distance > 0.0)) return "max_relative_distance must be > 0";
  if (!(min_overlap >= 0.0 && min_overlap <= 1.0)) return "min_overlap must be in [0, 1]";
  if (min_frames < 1) return "min_frames must be >= 1";
  if (max_frames < 0) return "max_frames must be >= 0";
  if (!(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0)) {
    return "min_inlier_fraction must be in [0, 1]";
  }
  if (!(max_rms_growth == 0.0 || max_rms_growth > 1.0) || !std::isfinite(max_rms_growth)) {
    return "max_rms_growth must be 0 (off) or > 1";
  }
  return "";
}

std::string OdometryOptions::Check() const {
  if (num_levels < 1 || num_levels > 8) return "num_levels must be in [1, 8]";
  if (!(line_outlier_px >= 0.0)) return "line_outlier_px must be >= 0";
  if (!(line_consensus_max_cost_drop >= 0.0) || !std::isfinite(line_consensus_max_cost_drop)) {
    return "line_consensus_max_cost_drop must be >= 0 and finite";
  }
  if (!(line_prior_gate_px >= 0.0)) return "line_prior_gate_px must be >= 0";
  if (random_map_warmup_updates < 0) return "random_map_warmup_updates must be >= 0";
  if (!(retry_rms_ratio >= 1.0)) return "retry_rms_ratio must be >= 1";
  if (!(alternative_rotation_deg > 0.0 && alternative_rotation_deg < 45.0)) {
    return "alternative_rotation_deg must be in (0, 45)";
  }
  if (reinit_after_lost < 1) return "reinit_after_lost must be >= 1";
  if (reinit_min_points < 0) return "reinit_min_points must be >= 0";
  if (mapping_queue_size < 1) return "mapping_queue_size must be >= 1";
  if (mapping_lag < 0) return "mapping_lag must be >= 0";
  if (!(init_depth_idepth_var >= 0.0)) return "init_depth_idepth_var must be >= 0";
  if (bootstrap_passes < 1) return "bootstrap_passes must be >= 1";
  if (!(bootstrap_idepth_var > 0.0) || !std::isfinite(bootstrap_idepth_var)) {
    return "bootstrap_idepth_var must be positive and finite";
  }
  if (bootstrap_passes > 1 && init_depth_idepth_var > 0.0) {
    return "bootstrap_passes > 1 refines the monocular start and cannot be combined with "
           "init_depth_idepth_var";
  }
  if (!(two_view_min_parallax_deg > 0.0 && two_view_min_parallax_deg < 90.0)) {
    return "two_view_min_parallax_deg must be in (0, 90)";
  }
  if (!(two_view_min_rotation_free_parallax_px >= 0.0)) {
    return "two_view_min_rotation_free_parallax_px must be >= 0";
  }
  if (two_view_min_inliers < 8) return "two_view_min_inliers must be >= 8";
  if (two_view_max_frames < 1) return "two_view_max_frames must be >= 1";
  if (two_view_max_anchor < 0) return "two_view_max_anchor must be >= 0";
  if (!(two_view_corner_quality > 0.0 && two_view_corner_quality < 1.0)) {
    return "two_view_corner_quality must be in (0, 1)";
  }
  if (!(two_view_corner_min_distance_px >= 0.0)) {
    return "two_view_corner_min_distance_px must be >= 0";
  }
  if (!(two_view_max_direction_std_deg > 0.0)) return "two_view_max_direction_std_deg must be > 0";
  if (two_view_stable_frames < 1) return "two_view_stable_frames must be >= 1";
  if (two_view_photometric_passes < 0) return "two_view_photometric_passes must be >= 0";
  if (!(two_view_photometric_outlier_factor >= 0.0)) {
    return "two_view_photometric_outlier_factor must be >= 0";
  }
  if (random_start_candidates < 1) return "random_start_candidates must be >= 1";
  if (random_start_frames < 2) return "random_start_frames must be >= 2";
  return "";
}

std::string OutputOptions::Check() const {
  if (iteration_images_every < 0) return "iteration_images_every must be >= 0";
  if (!(discontinuity_rel_step > 0.0)) return "discontinuity_rel_step must be > 0";
  if (discontinuity_radius_px < 0) return "discontinuity_radius_px must be >= 0";
  return "";
}

std::string BackendOptions::Check() const {
  const std::string edge_error = edge_ba.Check();
  if (!edge_error.empty()) return "edge_ba: " + edge_error;
  const std::string windowed_error = windowed_ba.Check();
  if (!windowed_error.empty()) return "windowed_ba: " + windowed_error;
  if (edge_ba.enabled && windowed_ba.enabled) {
    return "edge_ba and windowed_ba cannot both be enabled (both move the keyframe poses)";
  }
  return "";
}

std::string OdometryConfig::Check() const {
  const std::pair<const char*, std::string> sections[] = {
      {"dataset", dataset.Check()},      {"lines", lines.Check()},
      {"tracking", tracking.Check()},    {"mapping", mapping.Check()},
      {"keyframes", keyframes.Check()},  {"odometry", odometry.Check()},
      {"output", output.Check()},        {"backend", backend.Check()},
      {"evaluation", evaluation.Check()}};
  for (const auto& [name, error] : sections) {
    if (!error.empty()) return std::string(name) + ": " + error;
  }
  if (tracking.finest_level >= odometry.num_levels) {
    return "tracking.finest_level must be < odometry.num_levels";
  }
  return "";
}

}  // namespace pldvo
