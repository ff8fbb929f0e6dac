// Ground truth for evaluating the semi-dense mapping on synthetic sequences (tests and
// `pldvo mapeval`): traced keyframe edges and matched current lines from the scene's 3D edge
// segments and ground-truth poses (no frontend), and error statistics of a depth map against a
// ground-truth inverse depth.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_MAPPING_GROUND_TRUTH_H_
#define PLDVO_EXPERIMENTS_EVALUATION_MAPPING_GROUND_TRUTH_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/tracking/tracking_reference.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "frontend/edge_tracer.h"

namespace pldvo {

struct GroundTruthEdgeOptions {
  double min_length_px = 15.0;  // projected (clipped) segments shorter than this are left out
  int half_width_px = 1;        // EdgeTracer widening (the paper's one pixel)
  int border_px = 3;            // EdgeTracer border
  double near_z = 0.05;         // segments are clipped to z >= near_z (metres)
  // A traced pixel is visible when the GT depth in its 3x3 neighbourhood matches the 3D line's
  // depth at the pixel within this relative difference.
  double max_depth_rel_diff = 0.03;
  // Endpoint noise of the keyframe lines (pixels; 0: exact), their Sigma_l, and its seed. The
  // traced pixels follow the noisy lines, as the frontend's do.
  double line_sigma_px = 0.0;
  uint32_t seed = 0;
};

struct GroundTruthEdges {
  EdgeTrace trace;                           // ids index segments_in_ref
  std::vector<EdgeSegment> segments_in_ref;  // every input segment (traced or not)
  cv::Mat line_idepth;  // CV_32F: inverse depth of the 3D line at each traced pixel, else 0
  cv::Mat centre_mask;  // CV_8U: 255 at traced pixels within 0.5 px of the keyframe line
};

// Projects the segments (keyframe frame) into the keyframe, traces them, and keeps the traced
// pixels whose 3D line point is visible in `depth` (CV_32F z-depth, metres). The keyframe lines'
// endpoints carry options.line_sigma_px of noise (exact by default).
GroundTruthEdges MakeGroundTruthEdges(const std::vector<EdgeSegment>& segments_in_ref,
                                      const cv::Mat& depth, const PinholeCamera& camera,
                                      const GroundTruthEdgeOptions& options);

// The current-frame line of every traced edge: the segment projected with cur_from_ref, clipped
// to the image, endpoints perturbed by N(0, sigma_px^2) (seeded), l and Sigma_l from FitLine;
// unmatched when less than 10 px remain in the image. Indexed by edge id.
std::vector<MatchedLine> ProjectGroundTruthLines(const GroundTruthEdges& edges,
                                                 const PinholeCamera& camera,
                                                 const SE3& cur_from_ref, double sigma_px,
                                                 uint32_t seed);

// 1 / depth where depth > 0, else 0 (CV_32F).
cv::Mat InverseDepthFromDepth(const cv::Mat& depth);

struct DepthErrorStats {
  int count = 0;
  double median_rel_error = 0.0;  // median |d - d_gt| / d_gt
  double mean_rel_error = 0.0;
  double mean_nees = 0.0;      // mean (d - d_gt)^2 / V (1 for a consistent filter)
  double median_nees = 0.0;    // median; 0.455 for a consistent Gaussian filter
  double within_2sigma = 0.0;  // fraction with |d - d_gt| <= 2 sqrt(V) (0.954 if consistent)
  // The mean NEES splits into gross errors, NEES > kGrossNees (the chi^2(1) 99.9% quantile; a
  // fraction of 0.001 if consistent), and the bulk, whose mean NEES is 0.988 if consistent.
  double gross_fraction = 0.0;
  double bulk_mean_nees = 0.0;
};
constexpr double kGrossNees = 10.83;

// CV_8U mask of the pixels where the GT inverse depth (CV_32F, 0 = none) is continuous: 255 unless
// a pixel within `radius` (a square window) has a 4-neighbour step larger than max_rel_step times
// its inverse depth or lies next to a pixel without depth. At occlusion boundaries the GT of a
// pixel is one of two surfaces while its stereo patch sees both, so per-pixel errors there measure
// the boundary's sub-pixel position rather than the filter.
cv::Mat ContinuousDepthMask(const cv::Mat& gt_idepth, int radius, double max_rel_step);

// Statistics over the valid hypotheses with gt_idepth > 0 (CV_32F) and mask != 0 (CV_8U; empty =
// everywhere); with require_observed only hypotheses with at least one stereo observation. A
// monocular map is compared after scaling: s d against d_gt, with variance s^2 V.
DepthErrorStats EvaluateDepthMap(const SemiDenseDepthMap& map, const cv::Mat& gt_idepth,
                                 const cv::Mat& mask, bool require_observed = true,
                                 double scale = 1.0);
// The scale s = median(d_gt / d) of a monocular map over the hypotheses EvaluateDepthMap
// evaluates (no mask), or 0 when there are none.
double MedianInverseDepthRatio(const SemiDenseDepthMap& map, const cv::Mat& gt_idepth,
                               bool require_observed = true);

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_MAPPING_GROUND_TRUTH_H_
