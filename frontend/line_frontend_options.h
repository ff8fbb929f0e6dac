// Every option of the line frontend (seed paper Sec. VI-A(1)): detection, merging of broken
// segments, LBD description, keyframe -> frame matching and edge tracing. All follow the
// VisitFields pattern of core/options.h; defaults are documented next to each field and in
// docs/line_frontend.md.
#ifndef PLDVO_FRONTEND_LINE_FRONTEND_OPTIONS_H_
#define PLDVO_FRONTEND_LINE_FRONTEND_OPTIONS_H_

#include <string>

#include "core/options.h"

namespace pldvo {

struct LineDetectorOptions {
  // The paper uses LSD. EDLines is the default here: on the synthetic lowtex sequences it finds
  // more of the visible edges (recall 0.92 vs 0.77 at 10 gray levels of contrast, LSD ignores
  // gradients below ~5 gray levels/px) in a fifth of the time (docs/line_frontend.md).
  enum class Method {
    kLsd,      // cv::createLineSegmentDetector (LSD, von Gioi et al.; back in OpenCV >= 4.5.1)
    kEdLines,  // cv::ximgproc::EdgeDrawing::detectLines (EDLines, Akinlar & Topal 2011)
    kFld,      // cv::ximgproc::FastLineDetector (Lee et al. 2014)
  };
  Method method = Method::kEdLines;
  // Octave k is the image downsampled k times by cv::pyrDown (scale factor 2), so a pixel
  // centre x in octave k is 2^k x at full resolution. Detection runs on octaves
  // first_octave .. first_octave + num_octaves - 1. first_octave = 1 skips the full-resolution
  // image (about 4x cheaper, endpoints about 2x noisier).
  int first_octave = 0;
  int num_octaves = 2;
  // Segments shorter than this (full-resolution pixels) are discarded right after detection.
  double min_length_px = 8.0;
  // Standard deviation of a detected endpoint across the line at octave 0; an endpoint from
  // octave k has 2^k times this. Feeds Sigma_l (residuals/covariance_models.h).
  double endpoint_sigma_px = 0.5;
  // LSD: Gaussian subsampling factor applied inside LSD, gradient-angle tolerance (deg),
  // minimum density of aligned points in the rectangle, and log10(NFA) acceptance threshold.
  // lsd_quant bounds the gradient quantisation error; LSD ignores gradients below
  // lsd_quant / sin(angle tolerance) (5.2 gray levels per pixel at the defaults).
  double lsd_scale = 0.8;
  double lsd_quant = 2.0;
  double lsd_angle_tolerance_deg = 22.5;
  double lsd_density_threshold = 0.7;
  double lsd_log_eps = 0.0;
  // EDLines: gradient threshold of the edge map (EdgeDrawing's GradientThresholdValue), minimum
  // line length in octave pixels and the line-fit error threshold (pixels).
  int edlines_gradient_threshold = 20;
  int edlines_min_line_length = 10;
  double edlines_line_fit_error = 1.0;
  // EDLines' a-contrario validation (NFA) of every fitted line. Off saves a quarter of the
  // detection time on textured frames, but the unvalidated texture lines cost odometry accuracy
  // there (docs/line_frontend.md, "Cheaper detection and description").
  bool edlines_nfa_validation = true;
  // FLD: minimum length (octave pixels), line-fit distance threshold and Canny thresholds.
  int fld_length_threshold = 10;
  double fld_distance_threshold = 1.414;
  double fld_canny_low = 50.0;
  double fld_canny_high = 50.0;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Choice("method", &method,
             ChoiceNames<Method>{
                 {"lsd", Method::kLsd}, {"edlines", Method::kEdLines}, {"fld", Method::kFld}},
             "Segment detector: lsd | edlines | fld.");
    v.Field("first_octave", &first_octave,
            "Finest octave detected on (0 = full resolution; octave k is 2^-k scale).");
    v.Field("num_octaves", &num_octaves, "Number of octaves detected on (scale factor 2).");
    v.Field("min_length_px", &min_length_px,
            "Detections shorter than this (full-resolution px) are dropped before merging.");
    v.Field("endpoint_sigma_px", &endpoint_sigma_px,
            "Endpoint standard deviation at octave 0 (px); scaled by 2^octave. Feeds Sigma_l.");
    v.Field("lsd_scale", &lsd_scale, "LSD internal Gaussian subsampling factor.");
    v.Field("lsd_quant", &lsd_quant,
            "LSD gradient quantisation bound; gradients below quant / sin(tolerance) are ignored.");
    v.Field("lsd_angle_tolerance_deg", &lsd_angle_tolerance_deg,
            "LSD gradient angle tolerance (deg).");
    v.Field("lsd_density_threshold", &lsd_density_threshold,
            "LSD minimum density of aligned points in a rectangle.");
    v.Field("lsd_log_eps", &lsd_log_eps, "LSD detection threshold -log10(NFA) > lsd_log_eps.");
    v.Field("edlines_gradient_threshold", &edlines_gradient_threshold,
            "EDLines gradient threshold of the edge map.");
    v.Field("edlines_min_line_length", &edlines_min_line_length,
            "EDLines minimum line length (octave px).");
    v.Field("edlines_line_fit_error", &edlines_line_fit_error,
            "EDLines line-fit error threshold (px).");
    v.Field("edlines_nfa_validation", &edlines_nfa_validation,
            "EDLines a-contrario (NFA) validation of fitted lines.");
    v.Field("fld_length_threshold", &fld_length_threshold, "FLD minimum length (octave px).");
    v.Field("fld_distance_threshold", &fld_distance_threshold,
            "FLD line-fit distance threshold (px).");
    v.Field("fld_canny_low", &fld_canny_low, "FLD first Canny hysteresis threshold.");
    v.Field("fld_canny_high", &fld_canny_high, "FLD second Canny hysteresis threshold.");
  }
  std::string Check() const;
};

struct LineMergerOptions {
  // Merging on/off (off is the ablation that measures fragmentation).
  bool enabled = true;
  // Bucket grid: cell size of the midpoint grid (px) and number of orientation bins over the
  // full directed circle (segments carry a polarity, see line_segment.h).
  double cell_size_px = 32.0;
  int num_angle_bins = 36;
  // A pair merges when the directed angles differ by at most max_angle_deg, both endpoints
  // of the shorter lie within max_line_distance_px of the longer's line, and the gap between
  // their extents along that line is at most max_gap_px (overlap counts as gap 0).
  double max_angle_deg = 3.0;
  double max_line_distance_px = 1.5;
  double max_gap_px = 10.0;
  // Segments shorter than this after merging are dropped (full-resolution px).
  double min_length_px = 20.0;
  // At most this many segments are kept, the longest (0 = all): bounds the LBD and matching
  // time on cluttered frames, and long segments are the better localised and described ones.
  int max_segments = 150;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("enabled", &enabled, "Merge broken collinear segments.");
    v.Field("cell_size_px", &cell_size_px, "Cell size of the bucket grid (px).");
    v.Field("num_angle_bins", &num_angle_bins, "Orientation bins over 360 deg (directed).");
    v.Field("max_angle_deg", &max_angle_deg, "Maximum angle between merged segments (deg).");
    v.Field("max_line_distance_px", &max_line_distance_px,
            "Maximum distance of the shorter's endpoints to the longer's line (px).");
    v.Field("max_gap_px", &max_gap_px, "Maximum gap between merged segments along the line (px).");
    v.Field("min_length_px", &min_length_px,
            "Segments shorter than this after merging are dropped.");
    v.Field("max_segments", &max_segments,
            "Keep at most this many segments, the longest (0 = all; default 150).");
  }
  std::string Check() const;
};

struct LineDescriptorOptions {
  // LBD band width in octave pixels (BinaryDescriptor's widthOfBand_; 9 bands per region).
  int band_width = 7;
  // Segments are described at octave max(detection octave, min_octave). 1 (default) halves the
  // support region's length (and the time) of full-resolution segments and doubles its width
  // in full-resolution pixels, which on lowtex also raised the match recall (0.85 -> 0.90 at a
  // 10-frame gap, docs/line_frontend.md).
  int min_octave = 1;
  // Length of the support region along the segment, in octave pixels, centred on its midpoint:
  // min(segment length, max_support_px); 0 (default) = the whole segment. LBD's cost is
  // proportional to it: 32 halves the description time on textured frames but costs lowtex
  // matches (docs/line_frontend.md, "Cheaper detection and description").
  int max_support_px = 0;
  // Describe only what matching needs: a frame's segments that some keyframe segment gates
  // geometrically, and a keyframe's all at once when it first gates one (results are the same;
  // docs/line_frontend.md, "On demand").
  // false: Process describes every segment, e.g. when a frontend thread has a core to spare.
  bool on_demand = true;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("band_width", &band_width, "LBD band width (octave px).");
    v.Field("min_octave", &min_octave, "Describe at octave max(detection octave, min_octave).");
    v.Field("max_support_px", &max_support_px,
            "LBD support length along the segment (octave px, centred; 0 = whole segment).");
    v.Field("on_demand", &on_demand,
            "Describe only the segments that matching gates; false: all in Process (default "
            "true).");
  }
  std::string Check() const;
};

struct LineMatcherOptions {
  // Bucket grid of the current frame: cell size (px) and orientation bins over 360 deg.
  double cell_size_px = 40.0;
  int num_angle_bins = 18;
  // Gating without a prediction: a candidate must lie within search_radius_px of the
  // reference segment (perpendicular distance of its midpoint to the reference line, and
  // overlap of the extents along it grown by the radius) and its direction within
  // max_angle_deg.
  double search_radius_px = 80.0;
  double max_angle_deg = 20.0;
  // Gating with a prediction (the reference segment mapped into the current frame).
  double predicted_radius_px = 12.0;
  double predicted_max_angle_deg = 8.0;
  // Descriptor tests: Hamming distance (of 256 bits) at most max_hamming; best < ratio *
  // second best among the gated candidates; and mutual best when `mutual` is set.
  int max_hamming = 70;
  double ratio = 0.8;
  bool mutual = true;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("cell_size_px", &cell_size_px, "Cell size of the bucket grid (px).");
    v.Field("num_angle_bins", &num_angle_bins, "Orientation bins over 360 deg (directed).");
    v.Field("search_radius_px", &search_radius_px, "Search radius without a prediction (px).");
    v.Field("max_angle_deg", &max_angle_deg, "Maximum direction change without a prediction.");
    v.Field("predicted_radius_px", &predicted_radius_px, "Search radius around a prediction (px).");
    v.Field("predicted_max_angle_deg", &predicted_max_angle_deg,
            "Maximum direction difference to a prediction (deg).");
    v.Field("max_hamming", &max_hamming, "Maximum Hamming distance of a match (of 256 bits).");
    v.Field("ratio", &ratio, "Ratio test: best < ratio * second best.");
    v.Field("mutual", &mutual, "Require mutual best matches.");
  }
  std::string Check() const;
};

struct EdgeTracerOptions {
  // Pixels across the line added on each side of the rasterised centre pixel (the paper
  // widens by one pixel).
  int half_width_px = 1;
  // Pixels closer than this to the image border are not traced.
  int border_px = 1;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("half_width_px", &half_width_px, "Pixels added on each side across the line.");
    v.Field("border_px", &border_px, "Pixels this close to the border are not traced.");
  }
  std::string Check() const;
};

// Sub-pixel refit of the merged segments to the image's edge (frontend/line_refiner.h).
struct LineRefinerOptions {
  bool enabled = false;
  double sample_step_px = 2.0;  // spacing of the cross-profiles along the segment
  int search_radius_px = 2;     // profile half-length across the segment, pixels (1..8)
  double min_edge_step = 5.0;   // gray levels across one pixel at the edge point
  double min_point_fraction = 0.5;
  double max_angle_deg = 2.0;
  double max_shift_px = 1.5;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("enabled", &enabled,
            "Refit each merged segment to the sub-pixel gradient maxima across it (default "
            "false).");
    v.Field("sample_step_px", &sample_step_px, "Spacing of the cross-profiles (px).");
    v.Field("search_radius_px", &search_radius_px,
            "Half-length of a cross-profile (px, 1..8): how far off the edge may lie.");
    v.Field("min_edge_step", &min_edge_step,
            "Smallest intensity step across one pixel that counts as the edge (gray levels).");
    v.Field("min_point_fraction", &min_point_fraction,
            "Keep the segment unless this fraction of its profiles find the edge.");
    v.Field("max_angle_deg", &max_angle_deg, "Keep the segment when the refit turns it more.");
    v.Field("max_shift_px", &max_shift_px,
            "Keep the segment when the refit moves its midpoint more (px).");
  }
  std::string Check() const;
};

struct LineFrontendOptions {
  LineDetectorOptions detector;
  LineMergerOptions merger;
  LineRefinerOptions refiner;
  LineDescriptorOptions descriptor;
  LineMatcherOptions matcher;
  EdgeTracerOptions tracer;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Section("detector", &detector, "Line segment detection.");
    v.Section("merger", &merger, "Merging of broken segments.");
    v.Section("refiner", &refiner, "Sub-pixel refit of the merged segments.");
    v.Section("descriptor", &descriptor, "LBD descriptors.");
    v.Section("matcher", &matcher, "Keyframe -> frame matching.");
    v.Section("tracer", &tracer, "Edge tracing of matched keyframe lines.");
  }
  std::string Check() const;
};

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_FRONTEND_OPTIONS_H_
