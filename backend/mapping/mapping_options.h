// Options of the semi-dense keyframe mapping (Engel, Sturm, Cremers, "Semi-Dense Visual Odometry
// for a Monocular Camera", ICCV 2013, with the line-guided stereo and 3D line regularisation of
// Yang & Scherer, ICRA 2017, Sec. V). Every field documents its default and unit; the derivations
// are in docs/mapping.md. Units: inverse depth in 1/m, its variance in (1/m)^2, pixels at full
// resolution, intensities in gray levels (0..255).
#ifndef PLDVO_BACKEND_MAPPING_MAPPING_OPTIONS_H_
#define PLDVO_BACKEND_MAPPING_MAPPING_OPTIONS_H_

#include <string>

#include "core/options.h"

namespace pldvo {

struct MappingOptions {
  enum class Init { kRandom, kConstant };
  enum class OutlierModel { kValidityCounter, kInlierRatio };
  enum class LineRegularizationMethod { kRay1d, kPaper2d };
  enum class LineStereoSsd { kFallback, kRefine, kRefineMorePrecise, kFuse, kFirst };
  enum class IntervalEndMinimum { kAccept, kSkip, kOutlier };

  // ---- Pixel selection.
  // A keyframe pixel gets a depth hypothesis when |grad I| (central differences, gray levels per
  // pixel) is at least this, or when it lies on a traced edge.
  double gradient_threshold = 6.0;
  // Pixels closer than this to the image border get no hypothesis (the 5-sample SSD needs room).
  int border_px = 3;

  // ---- Initialisation of a first keyframe (Engel 2013 Sec. 2.1: random depth, large variance).
  Init init = Init::kRandom;
  double init_idepth = 0.5;      // kConstant: every hypothesis starts here, 1/m
  double init_idepth_min = 0.2;  // kRandom: uniform in [min, max], 1/m
  double init_idepth_max = 1.5;
  double init_idepth_var = 1.0;  // variance of every initial hypothesis, (1/m)^2 (sigma 1/m)
  int init_seed = 1;             // seed of the random initialisation

  // ---- Photometric epipolar stereo (Engel 2013 Sec. 2.2).
  // Image noise sigma_I in gray levels: sensor noise plus bilinear-interpolation error; enters
  // the photometric disparity variance 2 sigma_I^2 / g_p^2.
  double sigma_intensity = 2.0;
  // Raise sigma_I^2 of an SSD match to its residual variance, max(sigma_I^2, SSD / 8), SSD at
  // the sub-pixel match (docs/mapping.md, "Residual-scaled photometric noise").
  bool residual_intensity_noise = true;
  // sigma_l of Engel 2013: standard deviation in pixels of the epipolar line's position (pose and
  // calibration error); enters the geometric disparity variance sigma_l^2 / <g, l>^2 and the
  // line-guided variance (sigma_g of the paper).
  double sigma_epipolar_px = 0.5;
  // The search covers idepth +- search_sigmas * sigma, clipped to [min_idepth, max_idepth].
  double search_sigmas = 2.0;
  double min_idepth = 0.0;  // 1/m; 0 is a point at infinity
  double max_idepth = 5.0;  // 1/m (20 cm)
  // Search segments shorter than this are extended symmetrically (a few candidates for the
  // sub-pixel parabola); longer than max_search_length_px are skipped for this frame.
  double min_search_length_px = 3.0;
  // The SSD is evaluated about every ssd_search_step_px along the epipolar line: half a pixel
  // samples a texture up to the image's Nyquist frequency (docs/mapping.md, "Search step and
  // ambiguous matches"). The step is the patch's sample spacing in the current frame divided by
  // the nearest integer to spacing / ssd_search_step_px, so that steps share their samples.
  double ssd_search_step_px = 0.5;
  double max_search_length_px = 200.0;
  // |cos| of the angle between the keyframe gradient and the epipolar line below which the
  // geometric error is too large to search (Engel 2013: gradients orthogonal to the epipolar
  // line carry no disparity information).
  double min_gradient_epipolar_cos = 0.3;
  // Best 5-sample SSD: reject when its RMS per sample exceeds this (gray levels).
  double max_ssd_rms = 20.0;
  // Uniqueness: the best SSD outside +-2 px of the minimum must exceed ratio * best.
  double ssd_uniqueness_ratio = 1.5;
  // Add the spread of the search's other SSD minima, weighted by their likelihood, to the
  // observation variance (docs/mapping.md, "Search step and ambiguous matches").
  bool ssd_ambiguity_variance = true;
  // An SSD search whose best step is an end of the prior interval (idepth +- search_sigmas sigma)
  // has not found a minimum: the match may lie beyond that end, and the end's depth is no
  // evidence. kAccept: fuse it (Engel 2013); kSkip: no observation this frame; kOutlier: count it
  // as an outlier of the hypothesis (validity_decrement), so that a hypothesis the images keep
  // contradicting is dropped and searched again over the whole range. Ends at min_idepth or
  // max_idepth are minima. Both tie with kAccept end to end (docs/mapping.md, "Photometric
  // stereo").
  IntervalEndMinimum ssd_interval_end = IntervalEndMinimum::kAccept;
  // Skip a valid hypothesis' SSD search when even the observation's geometric variance (its
  // lower bound: sigma_epipolar_px over the gradient's cos, at the interval's largest disparity
  // Jacobian) exceeds this multiple of the hypothesis' variance: the fusion would shrink the
  // variance by less than 1 / (1 + ratio). Saves the searches of short baselines (as LSD-SLAM
  // skips short epipolar lines). 0: never skip (default; docs/mapping.md, "Photometric stereo").
  double uninformative_search_ratio = 0.0;
  // A pixel without a hypothesis gets one only when the observation's standard deviation is at
  // most this times the map's mean inverse depth (scale-free; LSD-SLAM creates below a fixed
  // variance of its normalised map). At millimetre baselines a search lands anywhere in the
  // range, and such hypotheses shrink the map keyframe by keyframe. 0: always create (so does a
  // map without hypotheses, which has no scale yet).
  double new_hypothesis_max_relative_sigma = 0.0;
  // A new hypothesis is the observation fused with a prior at the map's mean inverse depth whose
  // standard deviation is this times that mean (a Bayesian start: an observation at a millimetre
  // baseline, as uncertain as the prior, moves it half way). 0: the observation alone.
  double new_hypothesis_prior_relative_sigma = 1.0;
  // A 1-px keyframe step along the epipolar line must map to [1/s, s] px in the current frame
  // (strong scale change breaks the equidistant sampling).
  double max_epipolar_scale = 2.0;

  // ---- Line-guided stereo (paper Sec. V-A, eqs. 8-10).
  bool use_line_stereo = true;
  // Below this angle (degrees) between epipolar line and matched edge the intersection is
  // ill-conditioned (variance ~ 1/sin^2 theta); fall back to the SSD search.
  double min_line_epipolar_angle_deg = 10.0;
  // Check the line-guided match photometrically with one 5-sample SSD (max_ssd_rms).
  bool line_stereo_check_ssd = true;
  // How the 5-sample SSD search joins the line-guided stereo on a matched edge's pixel.
  // kFallback (the paper): only where the line-guided match is ill-conditioned. kRefine: also
  // re-search within the line match's idepth +- search_sigmas sigma_lambda (the line disambiguates,
  // the SSD localises) and take the SSD's match when that search succeeds; kRefineMorePrecise: only
  // when its variance is also the smaller one (the default: docs/mapping.md); kFuse: the
  // inverse-variance mean of both matches (two measurements of one depth with independent errors).
  // kFirst: search the whole prior interval first (as for a pixel without a line); the line-guided
  // match only where that search fails.
  LineStereoSsd line_stereo_ssd = LineStereoSsd::kRefineMorePrecise;
  // Add the keyframe line's perpendicular position error at the pixel (x^T Sigma_l1 x) to the
  // current line's in eq. 10, as a part of the observation's error that every line-guided
  // observation of the pixel shares (the same keyframe detection in every frame).
  bool line_stereo_keyframe_line_var = true;
  // A line-guided match outside the pixel's prior interval (idepth +- search_sigmas sigma) is
  // dropped, without the SSD fallback. false: only the global [min_idepth, max_idepth] bounds
  // apply and the EKF's outlier gate decides, as in the paper (the default: dropping them did
  // not pay on the development set, docs/deviations.md).
  bool line_stereo_prior_interval = false;
  // Line-guided stereo only for a pixel whose prior interval (idepth +- search_sigmas sigma)
  // spans at least this many pixels of the epipolar line, or that has no observation yet; a
  // narrower hypothesis is searched by the SSD within its interval: the line converges a
  // hypothesis, the SSD refines it (docs/mapping.md, "Lines converge, the SSD refines").
  // 0 (default): the line-guided stereo wherever the line is well-conditioned, as the paper; 4
  // did not pay on the development set.
  double line_stereo_min_interval_px = 0.0;
  // Scale the current line's position error in eq. 10 (x'^T Sigma_l2 x') by s^2, s the line
  // noise scale that the tracked frame's point-to-line errors imply (Tracker,
  // EstimateLineNoiseScale, whose model is that same term; the update's `line_cov_scale`): lines
  // noisier than the detector's model give less certain depths. false: Sigma_l2 as fitted
  // (paper.yaml).
  bool line_stereo_estimated_line_noise = true;
  // A match is left out for a frame when more than this fraction of its edge's hypotheses (and
  // at least line_match_min_votes of them) put the intersection outside their prior interval: a
  // wrong match (docs/mapping.md, "Wrong frontend matches on textured"). 1 = off.
  double line_match_max_outside_fraction = 1.0;
  int line_match_min_votes = 10;

  // ---- EKF fusion and outliers (Engel 2013 Sec. 2.3).
  // rho of the correlated-error fusion (SemiDenseDepthMap::Fuse, docs/mapping.md): the fraction
  // of a stereo observation's variance (SSD or line-guided) that is shared by all stereo
  // observations of the pixel (the same patch and edge matched over similar baselines), so that
  // the fused variance has the floor rho V_obs instead of shrinking as 1/n. 0 = independent
  // errors (the EKF of Engel 2013). 0.1: the smallest shared fraction measured on six
  // synthetic scenes (0.08-0.43; docs/mapping.md, "Correlated observation errors").
  double stereo_error_correlation = 0.1;
  // An observation further than gate sigmas from the prior (sqrt(V + V_obs)) is an outlier.
  double outlier_gate_sigmas = 2.0;
  int validity_initial = 20;   // validity counter of a new hypothesis
  int validity_increment = 5;  // per fused observation
  int validity_decrement = 5;  // per outlier; the hypothesis is dropped when it reaches <= 0
  int validity_max = 100;
  // How fusion treats outliers. kValidityCounter: the hard gate above and the validity counter
  // (Engel 2013). kInlierRatio: the Gaussian x uniform mixture of Vogiatzis & Hernandez (IVC
  // 2011), as in SVO/REMODE: each observation is an inlier N(D, V_obs) with probability pi or
  // uniform on [min_idepth, max_idepth]; the posterior is approximated by N(D | mu, V) Beta(pi |
  // a, b), with no hard gate (SemiDenseDepthMap::Fuse).
  OutlierModel outlier_model = OutlierModel::kValidityCounter;
  // kInlierRatio: the Beta prior of a new hypothesis, a = b = this (SVO: 10).
  double inlier_prior_count = 10.0;
  // kInlierRatio: a hypothesis whose expected inlier ratio a / (a + b) falls below this is
  // dropped (SVO: 0.1).
  double min_inlier_ratio = 0.1;
  int blacklist_threshold = 5;  // a pixel whose stereo failed this often is no longer searched
  // Stripes the per-pixel passes (stereo search and fusion, removal, filling, smoothing) are split
  // into, run on OpenCV's thread pool (cv::parallel_for_); every pixel's result is its own, so the
  // map does not depend on it. 0: as many as the pool has threads (cv::getNumThreads); 1: the
  // calling thread alone.
  int num_threads = 0;

  // ---- Regularisation (Engel 2013 Sec. 2.3).
  bool regularize = true;
  int regularization_radius = 2;  // (2r+1)^2 window
  // Neighbours further than this many sigmas (sqrt(V_i + V_j)) apart do not smooth each other.
  double regularization_gate_sigmas = 2.0;
  // Outlier removal: a hypothesis with fewer compatible valid neighbours is dropped.
  int min_neighbors_keep = 2;
  // Hole filling: an invalid candidate with at least this many valid neighbours gets their
  // inverse-variance weighted mean with variance init_idepth_var.
  int min_neighbors_fill = 8;

  // ---- 3D line regularisation (paper Sec. V-B, eqs. 11-13). Off by default: on the development
  // set it made points_lines worse on most sequences (docs/mapping.md, "3D line regularisation");
  // paper.yaml and the ablation `mapping.line_regularization=true` keep it.
  bool line_regularization = false;
  // kRay1d: the fit along the pixels' rays with the 1-D Mahalanobis gate in inverse depth
  // (LineRegularizer, header comment). kPaper2d: the paper's eqs. 11-13, RANSAC with the 2-D
  // Mahalanobis distance of each point to the line in the edge plane and the closed-form
  // least-squares fit Y = X beta.
  LineRegularizationMethod line_regularization_method = LineRegularizationMethod::kRay1d;
  int line_ransac_iterations = 50;
  // Mahalanobis^2 inlier gate, (d_i - d_line_i)^2 / V_i; 6.63 is the 99% chi^2(1) quantile.
  double line_ransac_gate_chi2 = 6.63;
  int line_min_pixels = 10;            // edges with fewer valid pixels are not regularised
  double line_min_inlier_ratio = 0.5;  // of the valid pixels
  int line_ransac_seed = 7;
  // Point-to-line rows only where the edge's depths agree with one 3D line: the same fit (with
  // or without line_regularization) unlinks the valid pixels it rejects from their edge in the
  // map tracking reads, and all of an edge's valid pixels when the edge has too few inliers;
  // their photometric rows stay. An occluding edge's traced band holds the far surface's
  // depths on one side, which move unlike the edge when the camera translates.
  bool line_depth_gate = false;

  // ---- Propagation to a new keyframe (Engel 2013 Sec. 2.4).
  // sigma_p^2 added to every propagated variance, (1/m)^2.
  double propagation_var = 1e-4;
  // Propagated hypotheses whose keyframe intensities differ by more than this are dropped
  // (occlusion or wrong depth).
  double max_propagation_intensity_diff = 25.0;

  // ---- Tracking reference (reference_builder.h).
  // At most this many points per pyramid level, evenly spaced in raster order (0 = all).
  int max_reference_points = 4000;
  // Point-to-line residuals (and the line gates) reproject each edge pixel's foot point on its
  // keyframe line instead of the traced pixel, which lies up to 1.5 px off the line while its
  // inverse depth is that of the line (ReferencePoint::pixel_on_edge; docs/odometry.md). Off by
  // default: measured no better end to end (docs/odometry.md, "Edge foot points").
  bool edge_foot_points = false;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("gradient_threshold", &gradient_threshold,
            "Semi-dense selection: |grad I| in gray levels per pixel (default 6).");
    v.Field("border_px", &border_px, "No hypotheses this close to the border (default 3).");
    v.Choice("init", &init, {{"random", Init::kRandom}, {"constant", Init::kConstant}},
             "First-keyframe initialisation: random or constant inverse depth.");
    v.Field("init_idepth", &init_idepth, "Constant initial inverse depth, 1/m (default 0.5).");
    v.Field("init_idepth_min", &init_idepth_min, "Random init lower bound, 1/m (default 0.2).");
    v.Field("init_idepth_max", &init_idepth_max, "Random init upper bound, 1/m (default 1.5).");
    v.Field("init_idepth_var", &init_idepth_var,
            "Variance of initial and hole-filled hypotheses, (1/m)^2 (default 1).");
    v.Field("init_seed", &init_seed, "Seed of the random initialisation (default 1).");
    v.Field("sigma_intensity", &sigma_intensity,
            "Image noise sigma_I incl. interpolation, gray levels (default 2).");
    v.Field("residual_intensity_noise", &residual_intensity_noise,
            "Raise sigma_I^2 of an SSD match to its residual SSD / 8 (default true).");
    v.Field("sigma_epipolar_px", &sigma_epipolar_px,
            "Epipolar line position sigma (pose error), pixels (default 0.5).");
    v.Field("search_sigmas", &search_sigmas, "Search idepth +- this many sigmas (default 2).");
    v.Field("min_idepth", &min_idepth, "Lower inverse-depth bound, 1/m (default 0).");
    v.Field("max_idepth", &max_idepth, "Upper inverse-depth bound, 1/m (default 5).");
    v.Field("min_search_length_px", &min_search_length_px,
            "Shorter search segments are extended to this, pixels (default 3).");
    v.Field("ssd_search_step_px", &ssd_search_step_px,
            "Step of the SSD search along the epipolar line, about this many pixels: the "
            "patch's sample spacing / round(spacing / step) (default 0.5).");
    v.Field("max_search_length_px", &max_search_length_px,
            "Longer search segments are skipped, pixels (default 200).");
    v.Field("min_gradient_epipolar_cos", &min_gradient_epipolar_cos,
            "Minimum |cos(gradient, epipolar line)| to search (default 0.3).");
    v.Field("max_ssd_rms", &max_ssd_rms, "Maximum RMS of the best SSD, gray levels (default 20).");
    v.Field("ssd_uniqueness_ratio", &ssd_uniqueness_ratio,
            "Second-best SSD (> 2 px away) must exceed ratio * best (default 1.5).");
    v.Field("ssd_ambiguity_variance", &ssd_ambiguity_variance,
            "Add the weighted spread of the other SSD minima to the variance (default true).");
    v.Choice("ssd_interval_end", &ssd_interval_end,
             {{"accept", IntervalEndMinimum::kAccept},
              {"skip", IntervalEndMinimum::kSkip},
              {"outlier", IntervalEndMinimum::kOutlier}},
             "SSD best at an end of the prior interval (not min_idepth / max_idepth): fuse it "
             "(accept, Engel 2013; default), no observation (skip), or an outlier of the "
             "hypothesis (outlier).");
    v.Field("uninformative_search_ratio", &uninformative_search_ratio,
            "Skip a hypothesis' SSD search when the observation's geometric variance exceeds "
            "ratio x its variance (0: never; default 0).");
    v.Field("new_hypothesis_max_relative_sigma", &new_hypothesis_max_relative_sigma,
            "Create a hypothesis only when the observation's standard deviation is at most this "
            "times the map's mean inverse depth (0: always; default 0).");
    v.Field("new_hypothesis_prior_relative_sigma", &new_hypothesis_prior_relative_sigma,
            "Fuse a new hypothesis with a prior at the map's mean inverse depth of standard "
            "deviation this times that mean (0: the observation alone; default 1).");
    v.Field("max_epipolar_scale", &max_epipolar_scale,
            "Maximum scale change along the epipolar line (default 2).");
    v.Field("use_line_stereo", &use_line_stereo, "Line-guided stereo on matched edges.");
    v.Field("min_line_epipolar_angle_deg", &min_line_epipolar_angle_deg,
            "Below this epipolar/edge angle use the SSD search, degrees (default 10).");
    v.Field("line_stereo_check_ssd", &line_stereo_check_ssd,
            "Check line-guided matches with one 5-sample SSD (default true).");
    v.Choice("line_stereo_ssd", &line_stereo_ssd,
             {{"fallback", LineStereoSsd::kFallback},
              {"refine", LineStereoSsd::kRefine},
              {"refine_more_precise", LineStereoSsd::kRefineMorePrecise},
              {"fuse", LineStereoSsd::kFuse},
              {"first", LineStereoSsd::kFirst}},
             "SSD search on matched edges: only where the line is ill-conditioned (fallback, the "
             "paper), also within +- search_sigmas of the line's match (refine; "
             "refine_more_precise, the default: if its variance is smaller; fuse: the "
             "inverse-variance mean of both), or over the whole interval before the line "
             "(first).");
    v.Field("line_stereo_keyframe_line_var", &line_stereo_keyframe_line_var,
            "Add the keyframe line's position error to eq. 10, shared by all of the pixel's "
            "line-guided observations (default true).");
    v.Field("line_stereo_prior_interval", &line_stereo_prior_interval,
            "Drop line-guided matches outside the prior interval idepth +- search_sigmas sigma; "
            "false leaves them to the EKF's outlier gate, as the paper (default false).");
    v.Field("line_stereo_min_interval_px", &line_stereo_min_interval_px,
            "Line-guided stereo only where the pixel's prior interval spans at least this many "
            "px (or it has no observation); narrower ones are searched by the SSD within it; "
            "0: always, as the paper (default 0).");
    v.Field("line_stereo_estimated_line_noise", &line_stereo_estimated_line_noise,
            "Scale the current line's position error in eq. 10 by the line noise the tracked "
            "frame's point-to-line errors imply (default true).");
    v.Field("line_match_max_outside_fraction", &line_match_max_outside_fraction,
            "Leave a line match out for a frame when more than this fraction of its edge's "
            "hypotheses put the intersection outside their prior interval (1 = off, default).");
    v.Field("line_match_min_votes", &line_match_min_votes,
            "Hypotheses an edge needs for that test (default 10).");
    v.Field("stereo_error_correlation", &stereo_error_correlation,
            "Fraction of a stereo observation's variance shared by all observations of the pixel "
            "(fusion floor; 0 = independent EKF; default 0.1).");
    v.Field("outlier_gate_sigmas", &outlier_gate_sigmas,
            "Observations further than this many sigmas are outliers (default 2).");
    v.Field("validity_initial", &validity_initial, "Validity counter of a new hypothesis (20).");
    v.Field("validity_increment", &validity_increment, "Validity gain per observation (5).");
    v.Field("validity_decrement", &validity_decrement, "Validity loss per outlier (5).");
    v.Field("validity_max", &validity_max, "Validity counter cap (100).");
    v.Choice("outlier_model", &outlier_model,
             {{"validity_counter", OutlierModel::kValidityCounter},
              {"inlier_ratio", OutlierModel::kInlierRatio}},
             "Outliers in fusion: hard gate and validity counter (Engel 2013), or the Gaussian x "
             "uniform inlier-ratio filter (Vogiatzis & Hernandez 2011).");
    v.Field("inlier_prior_count", &inlier_prior_count,
            "inlier_ratio: Beta(a, b) prior of a new hypothesis, a = b = this (10).");
    v.Field("min_inlier_ratio", &min_inlier_ratio,
            "inlier_ratio: drop hypotheses whose expected inlier ratio falls below this (0.1).");
    v.Field("blacklist_threshold", &blacklist_threshold,
            "Stereo failures after which a pixel is no longer searched (5).");
    v.Field("num_threads", &num_threads,
            "Stripes of the stereo, removal, filling and smoothing passes on OpenCV's thread pool; "
            "the map does not depend on it (0 = cv::getNumThreads(), default; 1 = the mapping "
            "thread alone).");
    v.Field("regularize", &regularize, "Smooth the map among compatible neighbours.");
    v.Field("regularization_radius", &regularization_radius, "Smoothing window radius (2).");
    v.Field("regularization_gate_sigmas", &regularization_gate_sigmas,
            "Neighbours further apart than this many sigmas do not interact (2).");
    v.Field("min_neighbors_keep", &min_neighbors_keep,
            "Drop hypotheses with fewer compatible neighbours (2).");
    v.Field("min_neighbors_fill", &min_neighbors_fill,
            "Fill invalid candidates with at least this many valid neighbours (8).");
    v.Field("line_regularization", &line_regularization,
            "3D line regularisation of edges, eqs. 11-13 (default false).");
    v.Field("line_depth_gate", &line_depth_gate,
            "Edge pixels whose inverse depths the edge's 3D line fit rejects (and every pixel of "
            "an edge with too few inliers) get no point-to-line rows (default false).");
    v.Choice("line_regularization_method", &line_regularization_method,
             {{"ray_1d", LineRegularizationMethod::kRay1d},
              {"paper_2d", LineRegularizationMethod::kPaper2d}},
             "ray_1d: fit along the rays, 1-D gate in inverse depth (default); paper_2d: the "
             "paper's eqs. 11-13, RANSAC with the 2-D Mahalanobis distance in the edge plane and "
             "the least-squares fit Y = X beta.");
    v.Field("line_ransac_iterations", &line_ransac_iterations, "RANSAC iterations per edge (50).");
    v.Field("line_ransac_gate_chi2", &line_ransac_gate_chi2,
            "Mahalanobis^2 inlier gate in inverse depth (6.63 = chi2(1) 99%).");
    v.Field("line_min_pixels", &line_min_pixels, "Minimum valid pixels of an edge (10).");
    v.Field("line_min_inlier_ratio", &line_min_inlier_ratio, "Minimum inlier ratio (0.5).");
    v.Field("line_ransac_seed", &line_ransac_seed, "Seed of the line RANSAC (7).");
    v.Field("propagation_var", &propagation_var,
            "sigma_p^2 added when propagating to a new keyframe, (1/m)^2 (1e-4).");
    v.Field("max_propagation_intensity_diff", &max_propagation_intensity_diff,
            "Drop propagated hypotheses whose intensities differ more, gray levels (25).");
    v.Field("max_reference_points", &max_reference_points,
            "Tracking reference points per pyramid level, evenly spaced (0 = all; default 4000).");
    v.Field("edge_foot_points", &edge_foot_points,
            "Point-to-line residuals reproject the edge pixels' foot points on their keyframe "
            "lines instead of the traced pixels (default false).");
  }
  // "" when valid, otherwise what is wrong (names the field).
  std::string Check() const;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_MAPPING_OPTIONS_H_
