// The mapping evaluation behind `pldvo mapeval` and tests/backend/depth_mapper_test.cc: a
// synthetic sequence with ground-truth poses and depth; a keyframe initialised at random is
// mapped with N tracked frames (GT poses) twice, with photometric stereo alone and with
// line-guided stereo (GT line matches: the scene's 3D edges projected with the GT poses, endpoint
// noise line_sigma_px; or, with frontend_lines, the line frontend's own detections and matches);
// then the 3D line regularisation, the smoothing and the propagation to the last frame are
// evaluated. See docs/mapping.md.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_MAPPING_EVALUATION_H_
#define PLDVO_EXPERIMENTS_EVALUATION_MAPPING_EVALUATION_H_

#include <functional>
#include <string>
#include <vector>

#include "backend/mapping/line_regularizer.h"
#include "backend/mapping/mapping_options.h"
#include "experiments/evaluation/mapping_ground_truth.h"
#include "experiments/synthetic/synthetic_sequence.h"
#include "frontend/line_frontend_options.h"

namespace pldvo {

struct MapEvalConfig {
  synthetic::SynthOptions synth;
  MappingOptions mapping;
  int keyframe_index = 0;
  int num_frames = 15;          // tracked frames fused into the keyframe
  int frame_stride = 2;         // frame k is keyframe_index + k * frame_stride
  double line_sigma_px = 0.25;  // endpoint noise of the GT current lines (main run, propagation)
  // Further line-guided runs, one per endpoint noise (the accuracy crossover with photometric).
  std::vector<double> line_sigma_sweep = {0.1, 0.5, 1.0};
  int line_seed = 17;
  // Endpoint noise of the keyframe's GT lines (pixels; 0: exact), seeded by line_seed.
  double keyframe_line_sigma_px = 0.0;
  // The keyframe's edges and every frame's matched lines from the line frontend (`lines`) instead
  // of the GT edges; the edge statistics are then the frontend's traced centre pixels away from
  // GT depth discontinuities against the depth image. Needs an empty line_sigma_sweep.
  bool frontend_lines = false;
  // frontend_lines only: leave out the matches that the depth image and the GT pose call wrong
  // (JudgeLineMatchByDepth): the line-guided stereo with an oracle matcher.
  bool drop_wrong_matches = false;
  // frontend_lines only: each kept match's current segment replaced by its keyframe segment moved
  // with the depth image and the GT pose (ExactCurrentSegment; Sigma_l as the detected segment's
  // octave gives), matches that do not transfer left out: the current frame's detection error
  // removed, the keyframe segment's kept.
  bool exact_current_lines = false;
  LineFrontendOptions lines;
  // Best of this many timings of the edge stereo with wide priors (0 skips the timing).
  int speed_repetitions = 5;
  // ContinuousDepthMask: a GT inverse-depth step larger than this fraction between 4-neighbours
  // is a discontinuity; pixels within discontinuity_radius_px of one are left out of
  // `continuous` (3 = the 5-sample SSD's half-length plus the bilinear interpolation pixel).
  double discontinuity_rel_step = 0.02;
  int discontinuity_radius_px = 3;
  // When not empty: the line-guided keyframe map is written there (inverse-depth PNGs raw and
  // regularised, PLY point cloud). Not a config key.
  std::string out_dir;

  // Textured preset, 320x240, fx = fy = 262.5. The mapping noise model matches the experiment:
  // sigma_intensity = the rendered noise (1 gray level); sigma_epipolar_px = 0.1 since the poses
  // are exact (the library default 0.5 px models tracking error).
  MapEvalConfig();
  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("keyframe_index", &keyframe_index, "Index of the keyframe in the sequence.");
    v.Field("num_frames", &num_frames, "Tracked frames fused into the keyframe.");
    v.Field("frame_stride", &frame_stride, "Frame k is keyframe_index + k * frame_stride.");
    v.Field("line_sigma_px", &line_sigma_px, "Endpoint noise of the GT current lines, pixels.");
    v.Field("line_seed", &line_seed, "Seed of that noise.");
    v.Field("keyframe_line_sigma_px", &keyframe_line_sigma_px,
            "Endpoint noise of the keyframe's GT lines, pixels (0: exact).");
    v.Field("speed_repetitions", &speed_repetitions,
            "Best of this many timings of the wide-prior edge stereo (0 skips it).");
    v.Field("discontinuity_rel_step", &discontinuity_rel_step,
            "GT inverse-depth step between neighbours that is a discontinuity (fraction).");
    v.Field("discontinuity_radius_px", &discontinuity_radius_px,
            "Pixels this close to a GT discontinuity are not `continuous`.");
    v.Field("line_sigma_sweep", &line_sigma_sweep,
            "Endpoint noises of additional line-guided runs, pixels.");
    v.Field("frontend_lines", &frontend_lines,
            "Edges and line matches from the line frontend instead of GT (needs "
            "line_sigma_sweep=[]).");
    v.Field("drop_wrong_matches", &drop_wrong_matches,
            "frontend_lines: leave out the matches the GT depth and pose call wrong (oracle).");
    v.Field("exact_current_lines", &exact_current_lines,
            "frontend_lines: the current lines are the keyframe segments moved with the GT depth "
            "and pose (no current detection error).");
    v.Section("synth", &synth, "Synthetic sequence.");
    v.Section("mapping", &mapping, "Mapping options.");
    v.Section("lines", &lines, "Line frontend (frontend_lines only).");
  }
  std::string Check() const;
};

// One mapping run (one stereo variant) and its evaluation.
struct MapEvalRun {
  DepthErrorStats all;         // every observed hypothesis vs the GT depth image
  DepthErrorStats continuous;  // `all` away from GT depth discontinuities (ContinuousDepthMask)
  DepthErrorStats edges;       // observed hypotheses on edge centre pixels vs the GT 3D line
  DepthErrorStats edges_line_regularized;  // the same after the 3D line regularisation
  DepthErrorStats all_smoothed;            // `all` after the inverse-variance smoothing
  LineRegularizationStats line_stats;
  double line_sigma_px = 0.0;
  double edge_stereo_us_per_pixel = 0.0;       // stereo wall time per processed edge pixel
  double first_frame_edge_us_per_pixel = 0.0;  // the same in the first frame (wide priors)
  double other_stereo_us_per_pixel = 0.0;
  int line_ok = 0, line_refined = 0, line_fallback = 0, line_rejected = 0, line_out_of_range = 0,
      line_matches_dropped = 0, line_matches_dropped_wrong = 0, ssd_ok = 0, outliers = 0;
  int candidates = 0, valid = 0;
};

struct MapEvalResult {
  bool frontend_lines = false;       // the edges below are the frontend's (else the GT edges)
  bool exact_current_lines = false;  // config.exact_current_lines
  // frontend_lines: the frontend's matches over all frames, judged by JudgeLineMatchByDepth
  // (before drop_wrong_matches).
  int matches_correct = 0, matches_wrong = 0, matches_unverifiable = 0;
  // frontend_lines: the correct matches' current segments against ExactCurrentSegment (the
  // detection error): distance of the detected line from the exact points at 1/4 and 3/4.
  int current_offset_count = 0;
  double current_offset_median_px = 0.0, current_offset_p90_px = 0.0;
  int width = 0, height = 0, num_edges = 0, num_edge_pixels = 0;
  double baseline_m = 0.0;  // keyframe-to-last-frame distance
  MapEvalRun photometric;
  MapEvalRun line_guided;              // at config.line_sigma_px
  std::vector<MapEvalRun> line_sweep;  // at config.line_sigma_sweep
  // The edge pixels both runs observed (each run's `edges` are its own observed pixels, and the
  // line-guided run observes pixels the SSD search does not): the two methods on the same pixels,
  // raw and after the 3D line regularisation.
  DepthErrorStats common_edges_photometric, common_edges_line;
  DepthErrorStats common_edges_photometric_line_regularized, common_edges_line_line_regularized;
  // Edge-pixel stereo time from the random initialisation against the last frame (wide priors,
  // one update; min over config.speed_repetitions, 0 when skipped), microseconds per edge pixel.
  double wide_prior_photometric_us = 0.0;
  double wide_prior_line_us = 0.0;
  DepthErrorStats propagated;  // line-guided map propagated to the last frame vs its GT depth
  int propagated_count = 0;
};

// Renders frame `index` of a sequence: synthetic::RenderFrame, or the tests' render cache
// (tests/render_cache.h), which renders a sequence once for all the evaluations of a test run.
using RenderFrameFunction =
    std::function<synthetic::RenderedFrame(const synthetic::SyntheticSequence&, int)>;

// Throws std::invalid_argument on an invalid config.
MapEvalResult RunMapEvaluation(const MapEvalConfig& config,
                               const RenderFrameFunction& render_frame = synthetic::RenderFrame);
std::string FormatMapEvalTable(const MapEvalResult& result);

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_MAPPING_EVALUATION_H_
