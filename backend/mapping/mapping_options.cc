#include "backend/mapping/mapping_options.h"

#include <cmath>
#include <sstream>

namespace pldvo {

std::string MappingOptions::Check() const {
  std::ostringstream error;
  if (gradient_threshold < 0.0) error << "gradient_threshold must be >= 0; ";
  if (border_px < 3) error << "border_px must be >= 3 (5-sample SSD); ";
  if (init_idepth <= 0.0) error << "init_idepth must be > 0; ";
  if (init_idepth_min <= 0.0 || init_idepth_max < init_idepth_min) {
    error << "init_idepth_min/max must satisfy 0 < min <= max; ";
  }
  if (init_idepth_var <= 0.0) error << "init_idepth_var must be > 0; ";
  if (sigma_intensity <= 0.0) error << "sigma_intensity must be > 0; ";
  if (sigma_epipolar_px < 0.0) error << "sigma_epipolar_px must be >= 0; ";
  if (search_sigmas <= 0.0) error << "search_sigmas must be > 0; ";
  if (min_idepth < 0.0 || max_idepth <= min_idepth) {
    error << "min_idepth/max_idepth must satisfy 0 <= min < max; ";
  }
  if (min_search_length_px < 0.0 || max_search_length_px <= min_search_length_px) {
    error << "min/max_search_length_px must satisfy 0 <= min < max; ";
  }
  // SearchEpipolarSsd keeps the SSD of every step in a buffer of 4096.
  if (!(ssd_search_step_px > 0.0 && ssd_search_step_px <= 1.0) ||
      max_search_length_px / ssd_search_step_px >= 4095.0) {
    error << "ssd_search_step_px must be in (0, 1] with max_search_length_px / step < 4095; ";
  }
  if (min_gradient_epipolar_cos < 0.0 || min_gradient_epipolar_cos >= 1.0) {
    error << "min_gradient_epipolar_cos must be in [0, 1); ";
  }
  if (max_ssd_rms <= 0.0) error << "max_ssd_rms must be > 0; ";
  if (ssd_uniqueness_ratio < 1.0) error << "ssd_uniqueness_ratio must be >= 1; ";
  if (!(uninformative_search_ratio >= 0.0 && std::isfinite(uninformative_search_ratio))) {
    error << "uninformative_search_ratio must be finite and >= 0; ";
  }
  if (!(new_hypothesis_max_relative_sigma >= 0.0 &&
        std::isfinite(new_hypothesis_max_relative_sigma))) {
    error << "new_hypothesis_max_relative_sigma must be finite and >= 0; ";
  }
  if (!(new_hypothesis_prior_relative_sigma >= 0.0 &&
        std::isfinite(new_hypothesis_prior_relative_sigma))) {
    error << "new_hypothesis_prior_relative_sigma must be finite and >= 0; ";
  }
  if (max_epipolar_scale < 1.0) error << "max_epipolar_scale must be >= 1; ";
  if (!(line_stereo_min_interval_px >= 0.0)) error << "line_stereo_min_interval_px must be >= 0; ";
  if (min_line_epipolar_angle_deg < 0.0 || min_line_epipolar_angle_deg >= 90.0) {
    error << "min_line_epipolar_angle_deg must be in [0, 90); ";
  }
  if (!(line_match_max_outside_fraction > 0.0 && line_match_max_outside_fraction <= 1.0)) {
    error << "line_match_max_outside_fraction must be in (0, 1]; ";
  }
  if (line_match_min_votes < 1) error << "line_match_min_votes must be >= 1; ";
  if (!(stereo_error_correlation >= 0.0 && stereo_error_correlation < 1.0)) {
    error << "stereo_error_correlation must be in [0, 1); ";
  }
  if (outlier_gate_sigmas <= 0.0) error << "outlier_gate_sigmas must be > 0; ";
  if (validity_initial <= 0 || validity_increment < 0 || validity_decrement <= 0 ||
      validity_max < validity_initial) {
    error << "validity counters must satisfy initial > 0, increment >= 0, decrement > 0, "
             "max >= initial; ";
  }
  if (!(inlier_prior_count > 0.0)) error << "inlier_prior_count must be > 0; ";
  if (!(min_inlier_ratio >= 0.0 && min_inlier_ratio < 1.0)) {
    error << "min_inlier_ratio must be in [0, 1); ";
  }
  if (blacklist_threshold <= 0) error << "blacklist_threshold must be > 0; ";
  if (num_threads < 0) error << "num_threads must be >= 0; ";
  if (max_reference_points < 0) error << "max_reference_points must be >= 0; ";
  if (regularization_radius < 1) error << "regularization_radius must be >= 1; ";
  if (regularization_gate_sigmas <= 0.0) error << "regularization_gate_sigmas must be > 0; ";
  if (min_neighbors_keep < 0 || min_neighbors_fill < 1) {
    error << "min_neighbors_keep must be >= 0 and min_neighbors_fill >= 1; ";
  }
  if (line_ransac_iterations < 1) error << "line_ransac_iterations must be >= 1; ";
  if (line_ransac_gate_chi2 <= 0.0) error << "line_ransac_gate_chi2 must be > 0; ";
  if (line_min_pixels < 2) error << "line_min_pixels must be >= 2; ";
  if (line_min_inlier_ratio <= 0.0 || line_min_inlier_ratio > 1.0) {
    error << "line_min_inlier_ratio must be in (0, 1]; ";
  }
  if (propagation_var < 0.0) error << "propagation_var must be >= 0; ";
  if (max_propagation_intensity_diff <= 0.0)
    error << "max_propagation_intensity_diff must be > 0; ";
  std::string message = error.str();
  if (!message.empty()) message = "MappingOptions: " + message.substr(0, message.size() - 2);
  return message;
}

}  // namespace pldvo
