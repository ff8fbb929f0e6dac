#include "frontend/line_frontend_options.h"

namespace pldvo {

std::string LineDetectorOptions::Check() const {
  if (first_octave < 0 || first_octave > 4) return "detector.first_octave must be in 0..4";
  if (num_octaves < 1 || num_octaves > 4) return "detector.num_octaves must be in 1..4";
  if (min_length_px < 0.0) return "detector.min_length_px must be >= 0";
  if (endpoint_sigma_px < 0.0) return "detector.endpoint_sigma_px must be >= 0";
  if (!(lsd_scale > 0.0 && lsd_scale <= 1.0)) return "detector.lsd_scale must be in (0, 1]";
  if (!(lsd_quant > 0.0)) return "detector.lsd_quant must be > 0";
  if (!(lsd_angle_tolerance_deg > 0.0 && lsd_angle_tolerance_deg < 90.0)) {
    return "detector.lsd_angle_tolerance_deg must be in (0, 90)";
  }
  if (!(lsd_density_threshold >= 0.0 && lsd_density_threshold <= 1.0)) {
    return "detector.lsd_density_threshold must be in [0, 1]";
  }
  if (edlines_gradient_threshold < 1) return "detector.edlines_gradient_threshold must be >= 1";
  if (edlines_min_line_length < 2) return "detector.edlines_min_line_length must be >= 2";
  if (edlines_line_fit_error <= 0.0) return "detector.edlines_line_fit_error must be > 0";
  if (fld_length_threshold < 2) return "detector.fld_length_threshold must be >= 2";
  if (fld_distance_threshold <= 0.0) return "detector.fld_distance_threshold must be > 0";
  if (fld_canny_low < 0.0 || fld_canny_high < 0.0) return "detector.fld_canny_* must be >= 0";
  return "";
}

std::string LineMergerOptions::Check() const {
  if (cell_size_px <= 0.0) return "merger.cell_size_px must be > 0";
  if (num_angle_bins < 1) return "merger.num_angle_bins must be >= 1";
  if (!(max_angle_deg >= 0.0 && max_angle_deg < 90.0)) return "merger.max_angle_deg in [0, 90)";
  if (max_line_distance_px < 0.0) return "merger.max_line_distance_px must be >= 0";
  if (max_gap_px < 0.0) return "merger.max_gap_px must be >= 0";
  if (min_length_px < 0.0) return "merger.min_length_px must be >= 0";
  if (max_segments < 0) return "merger.max_segments must be >= 0";
  return "";
}

std::string LineRefinerOptions::Check() const {
  if (!(sample_step_px >= 0.5)) return "refiner.sample_step_px must be >= 0.5";
  if (search_radius_px < 1 || search_radius_px > 8) return "refiner.search_radius_px in 1..8";
  if (!(min_edge_step > 0.0)) return "refiner.min_edge_step must be > 0";
  if (!(min_point_fraction >= 0.0 && min_point_fraction <= 1.0)) {
    return "refiner.min_point_fraction must be in [0, 1]";
  }
  if (!(max_angle_deg >= 0.0)) return "refiner.max_angle_deg must be >= 0";
  if (!(max_shift_px >= 0.0)) return "refiner.max_shift_px must be >= 0";
  return "";
}

std::string LineDescriptorOptions::Check() const {
  if (band_width < 1 || band_width > 20) return "descriptor.band_width must be in 1..20";
  if (min_octave < 0 || min_octave > 4) return "descriptor.min_octave must be in 0..4";
  if (max_support_px != 0 && max_support_px < 2) {
    return "descriptor.max_support_px must be 0 (whole segment) or >= 2";
  }
  return "";
}

std::string LineMatcherOptions::Check() const {
  if (cell_size_px <= 0.0) return "matcher.cell_size_px must be > 0";
  if (num_angle_bins < 1) return "matcher.num_angle_bins must be >= 1";
  if (search_radius_px < 0.0) return "matcher.search_radius_px must be >= 0";
  if (predicted_radius_px < 0.0) return "matcher.predicted_radius_px must be >= 0";
  if (!(max_angle_deg >= 0.0 && max_angle_deg <= 180.0)) return "matcher.max_angle_deg in [0, 180]";
  if (!(predicted_max_angle_deg >= 0.0 && predicted_max_angle_deg <= 180.0)) {
    return "matcher.predicted_max_angle_deg in [0, 180]";
  }
  if (max_hamming < 0 || max_hamming > 256) return "matcher.max_hamming must be in 0..256";
  if (!(ratio > 0.0 && ratio <= 1.0)) return "matcher.ratio must be in (0, 1]";
  return "";
}

std::string EdgeTracerOptions::Check() const {
  if (half_width_px < 0 || half_width_px > 5) return "tracer.half_width_px must be in 0..5";
  if (border_px < 0) return "tracer.border_px must be >= 0";
  return "";
}

std::string LineFrontendOptions::Check() const {
  for (const std::string& error : {detector.Check(), merger.Check(), refiner.Check(),
                                   descriptor.Check(), matcher.Check(), tracer.Check()}) {
    if (!error.empty()) return error;
  }
  return "";
}

}  // namespace pldvo
