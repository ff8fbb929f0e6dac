// Semi-dense keyframe mapping with line-guided stereo (Yang & Scherer, ICRA 2017, Sec. V, on
// Engel, Sturm, Cremers, ICCV 2013): the keyframe's inverse-depth filter is updated with every
// tracked frame, regularised, and propagated to the next keyframe.
//
//   DepthMapper mapper(camera, options);
//   mapper.InitializeKeyframe(image0, edges0);             // random / constant init
//   for each tracked frame k:
//     mapper.UpdateWithFrame(image_k, cur_from_ref_k, lines_k);  // stereo + EKF
//   SemiDenseDepthMap map = mapper.RegularizedMap(true, true);   // for tracking / output
//   mapper.PropagateToNewKeyframe(image_k, edges_k, new_from_old);
//
// UpdateWithFrame: every candidate pixel that is not blacklisted is matched against the frame
// (edge pixels with a matched line: line-guided stereo, eqs. 8-10, for the pixel's foot point on
// its keyframe line l1 (the ray of a traced pixel up to 1.5 px off l1 misses the 3D line; its
// nearest edge point is the foot point), falling back to the SSD search when the epipolar line
// and the edge are nearly parallel, and by default (options.line_stereo_ssd) replaced by the SSD
// search's match within +- 2 sigma of it where that is more precise; all other pixels: the SSD
// search over idepth +- 2 sigma) and the observation is fused by the EKF with correlated
// observation errors (SemiDenseDepthMap::Fuse, options.stereo_error_correlation); pixels
// without a hypothesis are searched over [min_idepth, max_idepth] and initialised from the
// observation. Then isolated hypotheses are removed and holes filled (depth_regularizer.h).
// Optionally (options.line_match_max_outside_fraction < 1) a match is left out for the frame when
// most of its edge's hypotheses put the line intersection outside their prior intervals.
// Smoothing and the 3D line regularisation act on a copy (RegularizedMap), never on the filter
// state, so that they do not count the same data twice.
#ifndef PLDVO_BACKEND_MAPPING_DEPTH_MAPPER_H_
#define PLDVO_BACKEND_MAPPING_DEPTH_MAPPER_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "backend/edge_ba/edge_ba_line_depth.h"
#include "backend/mapping/depth_propagation.h"
#include "backend/mapping/epipolar_stereo.h"
#include "backend/mapping/line_regularizer.h"
#include "backend/mapping/mapping_options.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/tracking/tracking_reference.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "frontend/edge_tracer.h"

namespace pldvo {

// Counts are 64-bit: summed over a run (MappingWorker::stereo_counts) they pass 2^31 after
// some 30 000 frames.
struct FrameUpdateStats {
  int64_t line_attempts = 0;      // edge pixels with a matched line
  int64_t line_ok = 0;            // fused or created from the line-guided match
  int64_t line_refined = 0;       // of which: refined (or fused) by the restricted SSD search
  int64_t line_fallback = 0;      // near-parallel: fell back to the SSD search
  int64_t line_rejected = 0;      // out of the prior interval or failed the SSD check
  int64_t line_out_of_range = 0;  // of which: outside the prior interval idepth +- 2 sigma
  // Edge pixels with a matched line searched by the SSD instead: their prior interval is
  // narrower than options.line_stereo_min_interval_px.
  int64_t line_narrow_prior = 0;
  // Edge ids whose match was left out because most of the edge's hypotheses put the
  // intersection outside their prior interval (options.line_match_max_outside_fraction).
  std::vector<int> dropped_line_matches;
  int64_t ssd_attempts = 0;
  int64_t ssd_ok = 0;
  // SSD searches whose best lay at an open end of the prior interval (options.ssd_interval_end).
  int64_t ssd_interval_end = 0;
  // SSD searches of hypotheses skipped as uninformative (options.uninformative_search_ratio).
  int64_t ssd_skipped = 0;
  int64_t fused = 0;             // EKF updates
  int64_t created = 0;           // new hypotheses from a full-range search
  int64_t not_created = 0;       // too uncertain (options.new_hypothesis_max_relative_sigma)
  int64_t outliers = 0;          // observations rejected by the EKF gate
  int64_t removed = 0;           // isolated hypotheses removed
  int64_t filled = 0;            // holes filled
  int64_t num_edge_pixels = 0;   // candidates on an edge that were processed
  double edge_stereo_ms = 0.0;   // wall time of the stereo on edge pixels
  double other_stereo_ms = 0.0;  // wall time of the stereo on all other pixels

  // Adds the counters of `other` (line_* to filled, num_edge_pixels; not the times or the
  // dropped matches).
  void AddCounts(const FrameUpdateStats& other);
};

// The line-guided match of a pixel and the SSD search's match within its interval
// (mapping.line_stereo_ssd=fuse) as one observation: the inverse-variance mean of two
// measurements of one inverse depth with independent errors. Only the line's share of the
// keyframe edge's error (shared_idepth_var) is common to other frames' observations.
StereoObservation FuseObservations(const StereoObservation& line, const StereoObservation& ssd);

// FuseLineDepths: what happened to the valid pixels on edges with a line.
struct LineDepthFusionStats {
  int pixels = 0;    // valid pixels whose edge has a line
  int skipped = 0;   // ray near-parallel to the line, behind the camera or missing it
  int fused = 0;     // EKF updates
  int outliers = 0;  // rejected by the EKF gate
};

// A correction of one hypothesis' inverse depth (ApplyIdepthCorrections).
struct IdepthCorrection {
  int pixel_index = -1;       // y * width + x
  double delta_idepth = 0.0;  // added to the mean, 1/m
};

class DepthMapper {
 public:
  // Throws std::invalid_argument when the camera or options are invalid.
  DepthMapper(const PinholeCamera& camera, const MappingOptions& options);

  // A first keyframe (8-bit or float gray image of the camera's size) initialised as
  // options.init says; `edges` is its traced edges (may be empty). Throws on size mismatch.
  void InitializeKeyframe(const cv::Mat& image, const EdgeTrace& edges);
  // A keyframe whose hypotheses come from a z-depth image (CV_32F metres) with variance
  // idepth_var (tests).
  void InitializeKeyframeFromDepth(const cv::Mat& image, const EdgeTrace& edges,
                                   const cv::Mat& depth, double idepth_var);

  // Stereo with a tracked frame and fusion. lines_in_cur[e] is the current line matched to the
  // keyframe edge e (the id in the keyframe's EdgeTrace); missing or unmatched entries use the
  // SSD search. `pose_covariance`: the tracked pose's error (tracking.pose_covariance), added
  // to the epipolar line's position error of every stereo observation; zero: the constant
  // mapping.sigma_epipolar_px alone. `line_cov_scale`: s^2 that multiplies the current lines'
  // covariances Sigma_l2 in eq. 10 (mapping.line_stereo_estimated_line_noise; 1: as fitted).
  FrameUpdateStats UpdateWithFrame(const cv::Mat& image, const SE3& cur_from_ref,
                                   const std::vector<MatchedLine>& lines_in_cur,
                                   const Matrix6d& pose_covariance = Matrix6d::Zero(),
                                   double line_cov_scale = 1.0);

  // Fuses the edge BA's optimised 3D lines (keyframe frame, with tangent covariances;
  // edge_ba_line_depth.h): every valid pixel whose edge id has a line gets the inverse depth of
  // the ray's closest approach to the line, with the variance J Sigma J^T, fused by
  // SemiDenseDepthMap::Fuse (EKF with its outlier gate). A ray missing the line by more than
  // kLineDepthMissPx pixels (as an angle, kLineDepthMissPx / max(fx, fy)) is skipped: traced
  // pixels lie up to 1.5 px off their keyframe line.
  static constexpr double kLineDepthMissPx = 2.0;
  LineDepthFusionStats FuseLineDepths(const std::vector<KeyframeLine>& lines);

  // The windowed BA's feedback into the keyframe's hypotheses (docs/windowed_ba.md):
  // - each hypothesis with a correction: its mean shifted by it (the BA's refined minus submitted
  //   inverse depth), the variance kept (the BA's posterior variance is not computed; keeping the
  //   filter's is conservative);
  // - with `new_from_old` (the keyframe's frame moved relative to the keyframe its map was
  //   propagated from), every other valid hypothesis re-expressed in the moved frame at its pixel:
  //   with r = K^-1 (x; 1) and c = (R r)_z, the point r / d becomes R r / d + t, so
  //   d' = d / (c + t_z d) and V' = (c / (c + t_z d)^2)^2 V (first order); the pixel's shift,
  //   below a pixel for the small corrections of a window, is not applied;
  // - with `idepth_scale` != 1 (the BA's scale against the map's, WindowedBAKeyframes::Apply),
  //   every other valid hypothesis then scaled: d' = s d, V' = s^2 V (the map at the BA's scale).
  // A result that is non-positive, above options.max_idepth or on an invalid pixel is skipped.
  // Returns the number of hypotheses changed.
  int ApplyIdepthCorrections(const std::vector<IdepthCorrection>& corrections,
                             const SE3* new_from_old = nullptr, double idepth_scale = 1.0);

  // A copy of the filter state with inverse-variance smoothing (if smooth) and the 3D line
  // regularisation of the keyframe's edges (if line_regularize).
  SemiDenseDepthMap RegularizedMap(bool smooth, bool line_regularize,
                                   LineRegularizationStats* stats = nullptr) const;

  // Makes `image` the keyframe with the propagated RegularizedMap(options.regularize,
  // options.line_regularization); new_from_old maps the old keyframe into the new one, and
  // `brightness` is the new keyframe's relative to the old one (PropagateDepthMap).
  PropagationStats PropagateToNewKeyframe(const cv::Mat& image, const EdgeTrace& edges,
                                          const SE3& new_from_old,
                                          const AffineBrightness& brightness = {});
  // The same from `old_regularized`, which must be this state's RegularizedMap(options.regularize,
  // options.line_regularization) (the mapping worker's last published map): not computed again.
  PropagationStats PropagateToNewKeyframe(const SemiDenseDepthMap& old_regularized,
                                          const cv::Mat& image, const EdgeTrace& edges,
                                          const SE3& new_from_old,
                                          const AffineBrightness& brightness = {});

  const SemiDenseDepthMap& depth_map() const { return map_; }
  const ImagePyramid& keyframe() const { return keyframe_; }
  const EdgeTrace& edges() const { return edges_; }
  // l1 of every edge id of the keyframe (a^2 + b^2 = 1; zero for ids the trace does not hold).
  const std::vector<Eigen::Vector3d>& keyframe_lines() const { return line_in_ref_by_id_; }
  const PinholeCamera& camera() const { return camera_; }
  const MappingOptions& options() const { return options_; }

 private:
  void SetKeyframe(const cv::Mat& image, const EdgeTrace& edges);
  // The search interval of a pixel: its hypothesis +- search_sigmas sigma within [min_idepth,
  // max_idepth], or that whole range without one; false when it is empty.
  bool PriorInterval(int index, double* idepth_min, double* idepth_max,
                     double* idepth_centre) const;
  // Line-guided stereo (LineGuidedStereo) of a pixel of edge e against lines_in_cur[e], from the
  // pixel's foot point on l1.
  StereoStatus ObserveOnLine(int index, const EpipolarGeometry& geometry,
                             const MatchedLine& line_in_cur, double idepth_min, double idepth_max,
                             const ImagePyramid* current, const EpipolarPatch* patch,
                             StereoObservation* observation) const;
  // Per edge id: the match is contradicted by the edge's hypotheses (at least
  // line_match_min_votes of them have an intersection inside or outside their prior interval,
  // and more than line_match_max_outside_fraction of those lie outside).
  std::vector<char> InconsistentLineMatches(const EpipolarGeometry& geometry,
                                            const std::vector<MatchedLine>& lines_in_cur) const;
  // The pixel's hypothesis is observed and its prior interval [idepth_min, idepth_max] spans
  // less than options.line_stereo_min_interval_px on the epipolar line.
  bool NarrowPrior(int index, const Eigen::Vector2d& pixel, const EpipolarGeometry& geometry,
                   double idepth_min, double idepth_max) const;
  // The SSD search of the valid hypothesis at index cannot shrink its variance by more than
  // 1 / (1 + options.uninformative_search_ratio): its observation's geometric variance alone (at
  // the largest disparity Jacobian over [idepth_min, idepth_max]) exceeds ratio x the variance.
  bool UninformativeSearch(int index, const Eigen::Vector2d& pixel,
                           const EpipolarGeometry& geometry, const EpipolarPatch& patch,
                           double idepth_min, double idepth_max) const;
  // How a pixel without a hypothesis gets one, from the map's mean inverse depth and the
  // options new_hypothesis_max_relative_sigma and new_hypothesis_prior_relative_sigma.
  struct NewHypothesisRule {
    double max_sigma = 0.0;  // largest observation standard deviation that creates (0: any)
    double prior_idepth = 0.0;
    double prior_var = 0.0;  // 0: the observation alone
  };
  NewHypothesisRule MakeNewHypothesisRule() const;
  // Stereo + fusion of one candidate pixel; a new hypothesis follows `rule`.
  void UpdatePixel(int index, const ImagePyramid& current, const EpipolarGeometry& geometry,
                   const std::vector<MatchedLine>& lines_in_cur, const NewHypothesisRule& rule,
                   FrameUpdateStats* stats);

  PinholeCamera camera_;
  MappingOptions options_;
  ImagePyramid keyframe_;
  EdgeTrace edges_;
  SemiDenseDepthMap map_;
  std::vector<Eigen::Vector3d> line_in_ref_by_id_;      // keyframe_lines()
  std::vector<Eigen::Matrix3d> line_cov_in_ref_by_id_;  // their Sigma_l1
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_DEPTH_MAPPER_H_
