// THE configuration of the odometry (`pldvo run`): one typed struct tree with the VisitFields
// pattern (core/options.h), so that one YAML file (experiments/configs/*.yaml), `--set key=value`
// overrides, the effective config.yaml of a run and the key table of docs/configuration.md all
// come from the same fields. Sections:
//   dataset    DatasetOptions (format, camera, ground_truth, normalize_exposure)
//   lines      LineFrontendOptions (detection, merging, LBD, matching, edge tracing)
//   tracking   TrackingOptions (solver, problem builder + weighting policy, levels, loss of track)
//   mapping    MappingOptions (semi-dense depth filter, line-guided stereo, propagation)
//   keyframes  KeyframeOptions (when a tracked frame becomes the new keyframe)
//   odometry   OdometryOptions (pyramid, line frontend on/off, alternative initial guesses,
//              lost-tracking recovery, threading)
//   output     OutputOptions (iteration images, keyframe depth PNGs, PLY point clouds)
//   backend    BackendOptions: edge_ba = EdgeBAOptions (windowed edge bundle adjustment),
//              windowed_ba = WindowedBAOptions (windowed photometric + line bundle adjustment)
// Defaults are experiments/configs/points_lines.yaml (it names no key whose value differs): the
// paper's method with this implementation's extras, which experiments/configs/paper.yaml switches
// off (docs/deviations.md); docs/config_keys.md lists every key.
#ifndef PLDVO_BACKEND_ODOMETRY_ODOMETRY_CONFIG_H_
#define PLDVO_BACKEND_ODOMETRY_ODOMETRY_CONFIG_H_

#include <string>

#include "backend/edge_ba/edge_ba_options.h"
#include "backend/mapping/mapping_options.h"
#include "backend/tracking/tracker.h"
#include "backend/windowed_ba/windowed_ba_options.h"
#include "core/dataset.h"
#include "core/evaluation.h"
#include "core/options.h"
#include "frontend/line_frontend_options.h"

namespace pldvo {

// When the current frame becomes a new keyframe (checked after every successfully tracked frame;
// LSD-SLAM / semi-dense VO criteria). The distance criterion is scale-free: the translation from
// the keyframe times the keyframe map's mean inverse depth, i.e. the baseline relative to the
// mean scene depth, so it means the same for any (arbitrary) monocular scale.
struct KeyframeOptions {
  // New keyframe when |t_cur_from_kf| * mean_idepth exceeds this (0.1: a baseline of 10% of the
  // mean scene depth).
  double max_relative_distance = 0.1;
  // New keyframe when fewer than this fraction of the keyframe's level-0 points reproject inside
  // the current image.
  double min_overlap = 0.7;
  // No new keyframe before this many frames were tracked against the current one (the depth
  // filter needs a few stereo observations before its map is propagated).
  int min_frames = 3;
  // Always a new keyframe after this many tracked frames (0 = no limit).
  int max_frames = 0;
  // New keyframe when fewer than this fraction of the tracked frame's valid rows are inliers
  // (TrackingResult::inlier_fraction): the keyframe no longer looks like the scene (exposure
  // drift, blur) though the frame is still tracked (tracking.min_inlier_fraction); 0 = off.
  double min_inlier_fraction = 0.5;
  // New keyframe when the frame's photometric misfit (the image noise its errors imply, gray
  // levels) exceeds this times the smallest misfit of the frames tracked against the keyframe:
  // the keyframe explains the image worse and worse (DSO uses 2x the first frame's RMS, Engel et
  // al. PAMI 2018 Sec. 3.1; the smallest is robust to the first frame's fresh map); 0 = off
  // (OdometryConfig sets 1.5).
  double max_rms_growth = 0.0;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("max_relative_distance", &max_relative_distance,
            "New keyframe when |t_cur_from_kf| * mean inverse depth exceeds this (default 0.1).");
    v.Field("min_overlap", &min_overlap,
            "New keyframe when fewer of the keyframe's points reproject inside the frame "
            "(default 0.7).");
    v.Field("min_frames", &min_frames,
            "Frames tracked against a keyframe before another may be created (default 3).");
    v.Field("max_frames", &max_frames,
            "New keyframe after this many tracked frames; 0 = no limit (default 0).");
    v.Field("min_inlier_fraction", &min_inlier_fraction,
            "New keyframe when fewer of the tracked frame's valid rows are inliers; 0 = off "
            "(default 0.5).");
    v.Field("max_rms_growth", &max_rms_growth,
            "New keyframe when the photometric misfit exceeds this times the smallest since the "
            "keyframe; 0 = off (default 1.5; sdvo and paper 0).");
  }
  std::string Check() const;
};

struct OdometryOptions {
  // Pyramid levels of the current frames and of the tracking reference (level 0 = full
  // resolution). tracking.coarsest_level is clamped to num_levels - 1.
  int num_levels = 5;
  // Run the line frontend (detection, LBD, matching, edge tracing). Off: no point-to-line
  // residuals, no line-guided stereo, no 3D line regularisation (the semi-dense VO baseline).
  bool use_lines = true;
  // Matching prediction: keyframe segments are mapped into the frame with the homography of the
  // predicted pose and a fronto-parallel plane at the keyframe's mean inverse depth.
  bool predict_line_matches = true;
  // Line-match verification after tracking: a matched line whose edge points (level 0),
  // reprojected with the tracked pose, lie at a median distance above this many pixels from it is
  // a wrong match (e.g. the neighbouring line of a repetitive pattern); such lines are unmatched
  // and the frame is tracked again from the result. The same unmatched lines are withheld from
  // the line-guided stereo. 0 = off.
  double line_outlier_px = 2.0;
  // The track again after unmatching: the finest level only from the tracked pose
  // (Tracker::Refine), or coarse to fine as the first track (false).
  bool line_outlier_refine_finest = true;
  // The same check before tracking at the constant-velocity prior, with this looser gate (the
  // prior is off by the acceleration since the last frame); 0 = off.
  double line_prior_gate_px = 2.0;
  // The photometric consensus check: after tracking with lines, a photometric-only solve at the
  // finest level starts from the result. When it lowers the photometric cost (whitened and
  // robust, 0.5 sum r^2, with the weights of the result's pose) by more than this, the line term
  // pulled the pose against the photometric evidence, and the frame keeps the photometric pose
  // (OdometryFrameResult::line_term_dropped). A pose the photometric term leaves free (a
  // texture-less direction) costs it nothing, so lines keep constraining it there.
  // chi^2_6 at 99% is 16.8, i.e. 8.4 in cost; 0 = off (the paper).
  double line_consensus_max_cost_drop = 8.4;
  // Stereo updates a randomly (re)initialised keyframe map (Engel 2013 Sec. 2.1: random inverse
  // depth, large variance) must have fused before tracking uses the point-to-line term; until
  // then frames are tracked photometric only. The first updates' depths are still mostly the
  // draws: the line rows can turn their random parallax into a pose error that the following
  // stereo updates build into the map (docs/bootstrap.md). Counted across keyframe switches that
  // propagate the map; maps from the two-view bootstrap or a depth image are exempt.
  // 0 = the line term from the first frame (the paper).
  int random_map_warmup_updates = 3;
  // Alternative initial guesses (besides the constant-velocity prior) are tried when the result
  // is lost, or when its final photometric RMS exceeds retry_rms_ratio times the running mean
  // over recent tracked frames (backend/odometry/retry_trigger.h): zero motion since the last good
  // frame, and that pose rotated by +-alternative_rotation_deg about the camera's x and y axes.
  // The best non-lost result wins by alternative_choice (backend/odometry/alternative_choice.h):
  // the most inlier rows at the finest level, where an alternative that ends further from the
  // first result than the prior moves the camera over the frame also needs a correlation no
  // lower (the default: a repetitive pattern's neighbouring period gains rows, not correlation);
  // or the most inlier rows alone, or times the intensity correlation, or more inlier rows and a
  // correlation no lower (a wrong pose can gain inlier rows where the images no longer correlate).
  bool try_alternatives = true;
  double retry_rms_ratio = 1.5;
  double alternative_rotation_deg = 2.0;
  enum class AlternativeChoice {
    kInlierRows,
    kCorrelatedInlierRows,
    kRowsAndCorrelation,
    kMotionGatedInlierRows
  };
  AlternativeChoice alternative_choice = AlternativeChoice::kMotionGatedInlierRows;
  // Lost tracking: a lost frame gets the constant-velocity extrapolation of the last good pose
  // (marked lost, not mapped). After this many consecutive lost frames the odometry
  // re-initialises: the current frame becomes a keyframe at the extrapolated pose, with the old
  // keyframe's map propagated to it, or a fresh random map when fewer than reinit_min_points
  // hypotheses survive the propagation.
  int reinit_after_lost = 3;
  int reinit_min_points = 500;
  // Mapping in its own thread (default). false: mapping runs on the caller's thread after each
  // frame; with wait_for_mapping both give the same run (mapping_lag).
  bool parallel_mapping = true;
  // Frame updates the map a frame is tracked against may lack: the newest `mapping_lag` frames'
  // stereo updates (since the last keyframe switch) are not in it yet, every older one is. Inline
  // they are held back; on the mapping thread (with wait_for_mapping) the tracking waits for
  // exactly that map, which lets mapping overlap `mapping_lag` frames of tracking and gives the
  // inline run's results. 0: every frame sees its predecessor's update (no overlap). 1 (default):
  // as accurate on the development set and faster at 640x480 (docs/odometry.md "Mapping lag").
  int mapping_lag = 1;
  // `pldvo run`: the per-image work of frame i + 1 (pyramid, line detection, merging and LBD;
  // FramePreparer) runs on the loading thread while frame i is tracked. It is a pure function of
  // the image, so results do not change; tracking_thread then leaves it out, and the frame period
  // (`total`) is the slower of the two stages. It pays where a core is free: with inline mapping
  // on textured frames; with the mapping thread on 2 cores the three threads share them and the
  // frame period grows (docs/odometry.md, "Threading"). false: all of it on the tracking thread.
  bool frontend_thread = false;
  // wait_for_mapping false: pending mapping updates kept when the mapping thread falls behind;
  // older pending frames are dropped (counted). Keyframe creations are never dropped.
  int mapping_queue_size = 2;
  // Wait for the mapping thread (mapping_lag) instead of dropping updates: every tracked frame
  // updates the map, so results do not depend on the machine's load (the wait is reported as
  // `wait`). false: real-time behaviour, the latest map is used and updates are dropped.
  bool wait_for_mapping = true;
  // Evaluation aid, off by default (monocular): initialise the first keyframe's map from the
  // first frame's depth image (TUM layout: 16-bit PNG, metres x 5000) with this inverse-depth
  // variance, which fixes the scale and removes the monocular initialisation; 0 = off.
  double init_depth_idepth_var = 0.0;
  // Bootstrap refinement (backend/odometry/bootstrap_refiner.h), monocular runs: before the run,
  // this many passes minus one over the first keyframe's frames, each starting from the map the
  // previous one ended with (the first from the random map); the run then starts from the last map
  // with inverse-depth variance bootstrap_idepth_var, relative to a median inverse depth of 1 (also
  // the variance of the two-view bootstrap's map, below).
  // 1 = off (default).
  int bootstrap_passes = 1;
  double bootstrap_idepth_var = 0.05;
  // Two-view bootstrap (backend/odometry/two_view_bootstrap.h), monocular runs: frame 0's map from
  // the first frame k <= two_view_max_frames where two_view_min_inliers tracked corners triangulate
  // (essential matrix) with a median parallax of two_view_min_parallax_deg and a median
  // rotation-free parallax (the part of the corners' motion that no rotation explains) of
  // two_view_min_rotation_free_parallax_px, the poses of frames 1..k bundle-adjusted, and stereo
  // with them; the run starts from it with bootstrap_idepth_var.
  // On by default (docs/bootstrap.md); when it fails (too few corners, too little parallax) the
  // run starts from the random map, exactly as with it off. bootstrap_passes > 1 and
  // init_depth_idepth_var > 0 ask for another start and replace it.
  bool two_view_bootstrap = true;
  double two_view_min_parallax_deg = 2.0;
  double two_view_min_rotation_free_parallax_px = 3.0;
  int two_view_min_inliers = 30;
  int two_view_max_frames = 90;
  // Where the corners are lost (fewer than two_view_min_inliers) before a second view, the start
  // begins again at the frame where they were lost, as long as that frame is at most
  // two_view_max_anchor; the frames before it are tracked backwards from its map
  // (backward_start.h). 0: frame 0 only. The cap bounds the start-up delay of the backward
  // tracking (docs/bootstrap.md measures 300 against 90).
  int two_view_max_anchor = 300;
  // ... and where the direction gate failed with the corners kept, again from the first frame
  // that passed the parallax gates (measured in docs/bootstrap.md).
  bool two_view_reanchor_after_direction_gate = true;
  // Its corners: cv::goodFeaturesToTrack's quality (relative to the strongest corner) and spacing;
  // the second view's adjusted translation direction: its largest standard deviation, and how
  // many consecutive frames' directions must agree to within that.
  double two_view_corner_quality = 0.001;
  double two_view_corner_min_distance_px = 5.0;
  double two_view_max_direction_std_deg = 3.0;
  int two_view_stable_frames = 3;
  // Passes of the direct refinement after the corners: frames 0..k (at most 8 evenly spaced)
  // and frame 0's map adjusted photometrically (the windowed BA's residuals, frame 0 hosting;
  // DSO's outlier test at the given factor, 0: off), the frames between moved with them, then
  // the map estimated again from the refined poses. 0 passes: the corners' poses only.
  int two_view_photometric_passes = 1;
  double two_view_photometric_outlier_factor = 0.0;
  // Where frame 0's stereo starts (step 5): kCornerMedian, every hypothesis at the corners'
  // median inverse depth (1 after the scale) with mapping.init_idepth_var, so that the start
  // depends on the images alone; kRandom, mapping.init's random map of mapping.init_seed.
  enum class TwoViewMapPrior { kCornerMedian, kRandom };
  TwoViewMapPrior two_view_map_prior = TwoViewMapPrior::kCornerMedian;
  // Best of several random starts (backend/odometry/random_start_choice.h), monocular runs that
  // start from the random map (no two-view start): the first random_start_frames frames run from
  // random_start_candidates initial maps (mapping.init_seed, + 1000 per further candidate) and
  // the run starts from the one whose frames fit best (fewest not tracked, then the highest mean
  // intensity correlation). 1 = the one map of mapping.init_seed (paper.yaml). With
  // random_start_corner_check, where the two-view start failed only at its direction gate, the
  // lowest epipolar error of its tracked corners decides instead of the correlation; with
  // random_start_reanchored_corners also where frame 0's corners were lost before the horizon,
  // with corners detected again where they were lost.
  int random_start_candidates = 5;
  int random_start_frames = 60;
  bool random_start_corner_check = true;
  bool random_start_reanchored_corners = false;
  // Solver comparison (docs/tracking.md): every tracked frame's final tracking problem (the same
  // reference, lines and initial pose) is solved a second time with this solver; its poses, RPE
  // and time are reported beside the run's (summary.json `compare_solver`,
  // trajectory_compare.txt) and do not influence the run. Not counted in tracking_thread. Frames
  // whose line term the consensus check dropped are not compared (their pose is not that
  // problem's).
  enum class CompareSolver { kNone, kCeres, kGaussNewton };
  CompareSolver compare_solver = CompareSolver::kNone;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("num_levels", &num_levels, "Pyramid levels of frames and reference (default 5).");
    v.Field("use_lines", &use_lines,
            "Run the line frontend; false is the photometric semi-dense VO baseline.");
    v.Field("predict_line_matches", &predict_line_matches,
            "Gate line matching around the segments predicted by the pose prior.");
    v.Field("line_outlier_px", &line_outlier_px,
            "Unmatch lines whose edge points reproject at a median distance above this (px) "
            "after tracking, and track again; 0 = off (default 2).");
    v.Field("line_outlier_refine_finest", &line_outlier_refine_finest,
            "After unmatching lines (line_outlier_px), re-solve only the finest level from the "
            "tracked pose; false re-tracks coarse to fine (default true).");
    v.Field("line_consensus_max_cost_drop", &line_consensus_max_cost_drop,
            "Drop a frame's line term when a photometric-only solve from its result lowers the "
            "photometric cost by more than this (0.5 sum r^2; 0 = off).");
    v.Field("random_map_warmup_updates", &random_map_warmup_updates,
            "Stereo updates a random initial map fuses before tracking uses the point-to-line "
            "term; earlier frames are tracked photometric only (0 = from the start, the paper; "
            "default 3).");
    v.Field("line_prior_gate_px", &line_prior_gate_px,
            "Unmatch lines whose edge points reproject at a median distance above this (px) at "
            "the pose prior, before tracking; 0 = off (default 2).");
    v.Field("try_alternatives", &try_alternatives,
            "Retry lost or high-residual frames from alternative initial guesses.");
    v.Field("retry_rms_ratio", &retry_rms_ratio,
            "Retry when the final photometric RMS exceeds this times the recent mean (1.5).");
    v.Field("alternative_rotation_deg", &alternative_rotation_deg,
            "Rotation of the alternative guesses about the camera x and y axes, deg (default 2).");
    v.Choice("alternative_choice", &alternative_choice,
             {{"inlier_rows", AlternativeChoice::kInlierRows},
              {"correlated_inlier_rows", AlternativeChoice::kCorrelatedInlierRows},
              {"rows_and_correlation", AlternativeChoice::kRowsAndCorrelation},
              {"motion_gated_inlier_rows", AlternativeChoice::kMotionGatedInlierRows}},
             "Which retried result wins: inlier_rows (most inlier rows) | correlated_inlier_rows "
             "(inlier rows x intensity correlation) | rows_and_correlation (more inlier rows and "
             "a correlation no lower) | motion_gated_inlier_rows (inlier_rows; an alternative "
             "further from the first result than the prior's motion over the frame also needs a "
             "correlation no lower) (default motion_gated_inlier_rows).");
    v.Field("reinit_after_lost", &reinit_after_lost,
            "Consecutive lost frames before re-initialising at the current frame (default 3).");
    v.Field("reinit_min_points", &reinit_min_points,
            "Propagated hypotheses needed to keep the map on re-initialisation (default 500).");
    v.Field("parallel_mapping", &parallel_mapping,
            "Mapping in its own thread; false runs it on the tracking thread (the same run with "
            "wait_for_mapping).");
    v.Field("mapping_lag", &mapping_lag,
            "Newest frame updates missing from the map a frame is tracked against, inline and "
            "on the mapping thread with wait_for_mapping (the same run); 0 = none (default 1).");
    v.Field("frontend_thread", &frontend_thread,
            "pldvo run: prepare frame i + 1 (pyramid, lines, LBD) on the loading thread while "
            "frame i is tracked (default false); results are unchanged.");
    v.Field("mapping_queue_size", &mapping_queue_size,
            "wait_for_mapping false: pending mapping updates kept before the oldest is dropped "
            "(default 2).");
    v.Field("wait_for_mapping", &wait_for_mapping,
            "Wait for the mapping thread (mapping_lag) instead of using the latest map and "
            "dropping updates (default true).");
    v.Field("init_depth_idepth_var", &init_depth_idepth_var,
            "Evaluation aid: > 0 initialises the first keyframe from the dataset's depth image "
            "with this inverse-depth variance, (1/m)^2; 0 = monocular random init (default).");
    v.Field("bootstrap_passes", &bootstrap_passes,
            "Monocular: passes over the first keyframe's frames, each re-estimating its map from "
            "the previous pass's map; the run starts from the last (1 = off, default).");
    v.Field("bootstrap_idepth_var", &bootstrap_idepth_var,
            "Inverse-depth variance of a refined or two-view start map, median inverse depth 1 "
            "(default 0.05).");
    v.Field(
        "two_view_bootstrap", &two_view_bootstrap,
        "Monocular: frame 0's map from the two-view geometry of tracked corners and stereo "
        "with the frames up to the second view; the run starts from it unless bootstrap_passes > 1 "
        "or init_depth_idepth_var > 0 asks for another start (default true).");
    v.Field("two_view_min_parallax_deg", &two_view_min_parallax_deg,
            "Two-view bootstrap: median parallax of the triangulated corners that makes a frame "
            "the second view, deg (default 2).");
    v.Field("two_view_min_rotation_free_parallax_px", &two_view_min_rotation_free_parallax_px,
            "Two-view bootstrap: median angle between the corners' rays in the second view and "
            "their rays in frame 0 turned by the best-fitting rotation, times the focal length, "
            "px: below it the essential matrix is fitted to noise (default 3).");
    v.Field("two_view_min_inliers", &two_view_min_inliers,
            "Two-view bootstrap: triangulated essential-matrix inliers needed (default 30).");
    v.Field("two_view_max_frames", &two_view_max_frames,
            "Two-view bootstrap: frames searched for the second view (default 90).");
    v.Field("two_view_max_anchor", &two_view_max_anchor,
            "Two-view bootstrap: where the corners are lost before a second view, the start "
            "begins again at the frame where they were lost, up to this frame; the frames before "
            "are tracked backwards from its map (0: frame 0 only; default 300).");
    v.Field("two_view_reanchor_after_direction_gate", &two_view_reanchor_after_direction_gate,
            "Two-view bootstrap: where the direction gate failed with the corners kept, start "
            "again from the first frame that passed the parallax gates, up to "
            "two_view_max_anchor (default true).");
    v.Field("two_view_corner_quality", &two_view_corner_quality,
            "Two-view bootstrap: smallest corner response relative to frame 0's strongest "
            "(cv::goodFeaturesToTrack qualityLevel, default 0.001).");
    v.Field("two_view_corner_min_distance_px", &two_view_corner_min_distance_px,
            "Two-view bootstrap: smallest distance between corners, px (default 5).");
    v.Field("two_view_max_direction_std_deg", &two_view_max_direction_std_deg,
            "Two-view bootstrap: largest standard deviation of the second view's translation "
            "direction after the bundle adjustment (1 px noise), deg; else the next frame is "
            "tried (default 3).");
    v.Field("two_view_stable_frames", &two_view_stable_frames,
            "Two-view bootstrap: consecutive frames passing the gates whose adjusted translation "
            "directions must agree to within two_view_max_direction_std_deg; the last is the "
            "second view (1 = no check, default 3).");
    v.Field("two_view_photometric_passes", &two_view_photometric_passes,
            "Two-view bootstrap: passes of photometric adjustment of frames 0..k (at most 8) "
            "and frame 0's map, each followed by the map's stereo again (0 = off, default 1).");
    v.Field("two_view_photometric_outlier_factor", &two_view_photometric_outlier_factor,
            "Two-view bootstrap: the photometric refinement leaves out a point's frame whose "
            "energy exceeds factor^2 x the median (DSO's outlier test; 0 = off, default 0).");
    v.Choice("two_view_map_prior", &two_view_map_prior,
             ChoiceNames<TwoViewMapPrior>{{"corner_median", TwoViewMapPrior::kCornerMedian},
                                          {"random", TwoViewMapPrior::kRandom}},
             "Two-view bootstrap: frame 0's stereo starts from the corners' median inverse "
             "depth (corner_median, default) or from the random map of mapping.init_seed "
             "(random).");
    v.Field(
        "random_start_candidates", &random_start_candidates,
        "Monocular runs from the random map: initial maps tried over the first "
        "random_start_frames frames; the run starts from the best fitting (1 = off; default 5).");
    v.Field("random_start_frames", &random_start_frames,
            "Frames each random-start candidate runs before the choice (default 60).");
    v.Field("random_start_corner_check", &random_start_corner_check,
            "Random-start choice: where the two-view start failed only at its direction gate, the "
            "candidate whose poses fit its tracked corners best (epipolar error) wins instead of "
            "the best intensity correlation (default true).");
    v.Field("random_start_reanchored_corners", &random_start_reanchored_corners,
            "Random-start corner check also where frame 0's corners were lost within "
            "random_start_frames: corners detected again where they were lost check the later "
            "frames (default false).");
    v.Choice("compare_solver", &compare_solver,
             ChoiceNames<CompareSolver>{{"none", CompareSolver::kNone},
                                        {"ceres", CompareSolver::kCeres},
                                        {"gauss_newton", CompareSolver::kGaussNewton}},
             "Also solve every frame's tracking problem with this solver and report the "
             "difference: none | ceres | gauss_newton (default none).");
  }
  std::string Check() const;
};

// What a run writes besides the trajectory (all off by default; see docs/odometry.md).
struct OutputOptions {
  // Tracking-iteration images (reprojected edge pixels over the current frame, the paper's
  // Fig. 2) of every N-th frame; 0 = none.
  int iteration_images_every = 0;
  // The inverse-depth map of every keyframe as a colour PNG when the keyframe is retired.
  bool keyframe_depth_png = false;
  // The semi-dense points of every keyframe (world frame) as a PLY when it is retired.
  bool keyframe_ply = false;
  // Every retired keyframe's map against the dataset's depth image of its frame (tum layout with
  // depth.txt: synthetic sequences, TUM RGB-D, ICL-NUIM), after a median scale alignment, one
  // row per keyframe in OUT/keyframe_maps.csv and medians in summary.json. Costs one depth-image
  // read per keyframe on the tracking thread.
  bool keyframe_map_error = false;
  // Its `continuous` columns leave out pixels within this many pixels of a GT inverse-depth step
  // larger than discontinuity_rel_step between 4-neighbours (as `pldvo mapeval`).
  double discontinuity_rel_step = 0.02;
  int discontinuity_radius_px = 3;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("iteration_images_every", &iteration_images_every,
            "Write tracking-iteration images of every N-th frame; 0 = none (default 0).");
    v.Field("keyframe_depth_png", &keyframe_depth_png,
            "Write each keyframe's inverse-depth map as PNG (default false).");
    v.Field("keyframe_ply", &keyframe_ply,
            "Write each keyframe's semi-dense points as PLY (default false).");
    v.Field("keyframe_map_error", &keyframe_map_error,
            "Evaluate each keyframe's map against the dataset's depth image (scale-aligned) into "
            "keyframe_maps.csv and summary.json (default false).");
    v.Field("discontinuity_rel_step", &discontinuity_rel_step,
            "keyframe_map_error: a GT inverse-depth step between neighbours larger than this "
            "fraction is a discontinuity (default 0.02).");
    v.Field("discontinuity_radius_px", &discontinuity_radius_px,
            "keyframe_map_error: pixels this close to a discontinuity are not `continuous` "
            "(default 3).");
  }
  std::string Check() const;
};

// Optimisation beside tracking (docs/edge_ba.md, docs/windowed_ba.md). At most one of the two
// runs: both move the same keyframe poses.
struct BackendOptions {
  EdgeBAOptions edge_ba;          // off by default
  WindowedBAOptions windowed_ba;  // off by default

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Section("edge_ba", &edge_ba, "Windowed edge bundle adjustment over the newest keyframes.");
    v.Section("windowed_ba", &windowed_ba,
              "Windowed photometric + line bundle adjustment over the newest keyframes.");
  }
  std::string Check() const;
};

struct OdometryConfig {
  // Defaults of the sub-structs, except the line detector: EDLines (at 640x480 about 4x faster
  // than LSD; measured in docs/odometry.md), tracking's image noise, estimated from the residuals
  // so that the balance of eqs. 5-6 does not move with the contrast (docs/tracking.md), and a new
  // keyframe when the photometric misfit grows 1.5x (docs/odometry.md, "Keyframes").
  OdometryConfig() {
    lines.detector.method = LineDetectorOptions::Method::kEdLines;
    tracking.problem.weighting.intensity_noise = NoiseSource::kEstimated;
    keyframes.max_rms_growth = 1.5;
  }

  DatasetOptions dataset;
  LineFrontendOptions lines;
  TrackingOptions tracking;
  MappingOptions mapping;
  KeyframeOptions keyframes;
  OdometryOptions odometry;
  OutputOptions output;
  BackendOptions backend;
  EvaluationOptions evaluation;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Section("dataset", &dataset, "Dataset reading (format, camera, ground truth, exposure).");
    v.Section("lines", &lines, "Line frontend: detection, merging, LBD, matching, tracing.");
    v.Section("tracking", &tracking, "Coarse-to-fine direct tracking against the keyframe.");
    v.Section("mapping", &mapping, "Semi-dense keyframe depth filter with line-guided stereo.");
    v.Section("keyframes", &keyframes, "Keyframe selection.");
    v.Section("odometry", &odometry, "Pipeline, lost-tracking recovery and threading.");
    v.Section("output", &output, "Optional outputs of `pldvo run`.");
    v.Section("backend", &backend,
              "Optimisation beside tracking (edge or photometric windowed bundle adjustment).");
    v.Section("evaluation", &evaluation,
              "Accuracy against the dataset's ground truth in summary.json (docs/evaluation.md).");
  }
  // "" when valid, otherwise the first section and what is wrong there.
  std::string Check() const;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_ODOMETRY_CONFIG_H_
