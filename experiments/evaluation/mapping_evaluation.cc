#include "experiments/evaluation/mapping_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/mapping/depth_map_io.h"
#include "backend/mapping/depth_mapper.h"
#include "backend/odometry/reference_builder.h"
#include "experiments/evaluation/line_match_ground_truth.h"
#include "experiments/evaluation/synthetic_pairs.h"
#include "frontend/line_frontend.h"

namespace pldvo {
namespace {

struct Frame {
  cv::Mat image;
  cv::Mat depth;
  SE3 world_from_cam;
};

// The keyframe's edges (the mapper's edge candidates) and the truth of the edge statistics.
struct KeyframeEdges {
  EdgeTrace trace;
  cv::Mat idepth;  // CV_32F: GT inverse depth of the evaluated edge pixels
  cv::Mat mask;    // CV_8U: the evaluated edge pixels
};

// The state a run ends in: its mapper and the map after the 3D line regularisation.
struct VariantState {
  std::unique_ptr<DepthMapper> mapper;
  SemiDenseDepthMap line_regularized;
};

// lines[k]: the matched lines of frames[k], indexed by keyframe edge id; wrong_matches[k][e]
// (frontend_lines, else empty): JudgeLineMatchByDepth called that match wrong. `state`
// (optional) receives the run's final state.
MapEvalRun RunVariant(const MapEvalConfig& config, bool line_stereo, double line_sigma_px,
                      const PinholeCamera& camera, const Frame& keyframe,
                      const std::vector<Frame>& frames, const KeyframeEdges& edges,
                      const std::vector<std::vector<MatchedLine>>& lines,
                      const std::vector<std::vector<char>>& wrong_matches = {},
                      VariantState* state = nullptr) {
  MappingOptions options = config.mapping;
  options.use_line_stereo = line_stereo;
  auto owned_mapper = std::make_unique<DepthMapper>(camera, options);
  DepthMapper& mapper = *owned_mapper;
  mapper.InitializeKeyframe(keyframe.image, edges.trace);
  MapEvalRun run;
  run.line_sigma_px = line_sigma_px;
  double edge_ms = 0.0, other_ms = 0.0;
  long edge_pixels = 0, other_pixels = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    const SE3 cur_from_ref = frames[k].world_from_cam.Inverse() * keyframe.world_from_cam;
    const FrameUpdateStats stats = mapper.UpdateWithFrame(frames[k].image, cur_from_ref, lines[k]);
    if (k == 0 && stats.num_edge_pixels > 0) {
      run.first_frame_edge_us_per_pixel = 1e3 * stats.edge_stereo_ms / stats.num_edge_pixels;
    }
    edge_ms += stats.edge_stereo_ms;
    other_ms += stats.other_stereo_ms;
    edge_pixels += stats.num_edge_pixels;
    run.line_ok += stats.line_ok;
    run.line_refined += stats.line_refined;
    run.line_fallback += stats.line_fallback;
    run.line_rejected += stats.line_rejected;
    run.line_out_of_range += stats.line_out_of_range;
    for (int edge : stats.dropped_line_matches) {
      ++run.line_matches_dropped;
      run.line_matches_dropped_wrong += k < wrong_matches.size() && wrong_matches[k][edge];
    }
    run.ssd_ok += stats.ssd_ok;
    run.outliers += stats.outliers;
  }
  const SemiDenseDepthMap& map = mapper.depth_map();
  // Candidates off the edges: processed every frame unless blacklisted (an upper bound on the
  // processed count, so other_stereo_us_per_pixel is a lower bound).
  for (int i = 0; i < map.num_pixels(); ++i) other_pixels += map.candidate(i) && map.edge_id(i) < 0;
  other_pixels *= static_cast<long>(frames.size());
  run.edge_stereo_us_per_pixel = edge_pixels > 0 ? 1e3 * edge_ms / edge_pixels : 0.0;
  run.other_stereo_us_per_pixel = other_pixels > 0 ? 1e3 * other_ms / other_pixels : 0.0;
  run.candidates = map.CountCandidates();
  run.valid = map.CountValid();
  const cv::Mat gt_idepth = InverseDepthFromDepth(keyframe.depth);
  run.all = EvaluateDepthMap(map, gt_idepth, cv::Mat());
  run.continuous = EvaluateDepthMap(map, gt_idepth,
                                    ContinuousDepthMask(gt_idepth, config.discontinuity_radius_px,
                                                        config.discontinuity_rel_step));
  run.edges = EvaluateDepthMap(map, edges.idepth, edges.mask);
  const SemiDenseDepthMap line_regularized = mapper.RegularizedMap(false, true, &run.line_stats);
  run.edges_line_regularized = EvaluateDepthMap(line_regularized, edges.idepth, edges.mask);
  run.all_smoothed = EvaluateDepthMap(mapper.RegularizedMap(true, false), gt_idepth, cv::Mat());
  if (state != nullptr) *state = {std::move(owned_mapper), line_regularized};
  return run;
}

// The evaluated edge pixels that both runs observed: the two stereo methods on the same pixels.
cv::Mat CommonEdgeMask(const cv::Mat& edge_mask, const SemiDenseDepthMap& a,
                       const SemiDenseDepthMap& b) {
  cv::Mat common = edge_mask.clone();
  for (int y = 0; y < common.rows; ++y) {
    for (int x = 0; x < common.cols; ++x) {
      const int i = a.Index(x, y);
      if (!a.observed(i) || !b.observed(i)) common.at<uint8_t>(y, x) = 0;
    }
  }
  return common;
}

// The GT lines of every frame at endpoint noise sigma_px (frame k seeded line_seed + k).
std::vector<std::vector<MatchedLine>> GroundTruthLinesPerFrame(
    const MapEvalConfig& config, const GroundTruthEdges& gt_edges, const PinholeCamera& camera,
    const Frame& keyframe, const std::vector<Frame>& frames, double sigma_px) {
  std::vector<std::vector<MatchedLine>> lines;
  for (size_t k = 0; k < frames.size(); ++k) {
    lines.push_back(ProjectGroundTruthLines(
        gt_edges, camera, frames[k].world_from_cam.Inverse() * keyframe.world_from_cam, sigma_px,
        static_cast<uint32_t>(config.line_seed + k)));
  }
  return lines;
}

// exact_current_lines: the keyframe segment `ref` in the current frame. Its points at 1/4 and
// 3/4 of its length (away from endpoints that may touch a depth edge) are lifted with the depth
// of their own pixel (TransferPixelByDepth, window 0: a window's nearest depth would move them
// on a slanted plane) and moved by the GT pose; the segment through them keeps ref's extent and
// gets Sigma_l for `octave`. False when a point does not transfer.
bool ExactCurrentSegment(const PinholeCamera& camera, const cv::Mat& depth, const SE3& cur_from_ref,
                         const LineSegment& ref, int octave, double endpoint_sigma_px,
                         LineSegment* cur) {
  Eigen::Vector2d quarter, three_quarters;
  if (!TransferPixelByDepth(camera, depth, cur_from_ref, ref.start + 0.25 * (ref.end - ref.start),
                            0, &quarter) ||
      !TransferPixelByDepth(camera, depth, cur_from_ref, ref.start + 0.75 * (ref.end - ref.start),
                            0, &three_quarters) ||
      (three_quarters - quarter).norm() < 0.5) {
    return false;
  }
  const Eigen::Vector2d half = 0.5 * (three_quarters - quarter);
  *cur = MakeLineSegment(quarter - half, three_quarters + half, octave,
                         endpoint_sigma_px * std::ldexp(1.0, octave));
  return true;
}

// frontend_lines: every keyframe segment traced (as the odometry does), every frame's segments
// matched to the keyframe's without a prediction; the edge statistics on the traced pixels within
// 0.5 px of their segment that `continuous` keeps, against the depth image. Every match is judged
// by JudgeLineMatchByDepth (counts in `result`, (*wrong_matches)[k][edge id] when wrong).
void FrontendLines(const MapEvalConfig& config, const Frame& keyframe,
                   const std::vector<Frame>& frames, const cv::Mat& gt_idepth,
                   const cv::Mat& continuous, const PinholeCamera& camera, KeyframeEdges* edges,
                   std::vector<std::vector<MatchedLine>>* lines,
                   std::vector<std::vector<char>>* wrong_matches, MapEvalResult* result) {
  LineFrontend frontend(config.lines);
  LineFrame keyframe_lines = frontend.Process(keyframe.image);
  std::vector<LineMatch> all(keyframe_lines.segments.size());
  for (size_t i = 0; i < all.size(); ++i) all[i].ref_index = static_cast<int>(i);
  edges->trace = frontend.TraceMatched(keyframe_lines, all);
  edges->idepth = gt_idepth;
  edges->mask = cv::Mat(gt_idepth.size(), CV_8U, cv::Scalar(0));
  for (const TracedLine& line : edges->trace.lines) {
    for (const Eigen::Vector2i& p : line.pixels) {
      if (std::abs(line.segment.SignedDistance(p.cast<double>())) <= 0.5 &&
          continuous.at<uint8_t>(p.y(), p.x()) != 0) {
        edges->mask.at<uint8_t>(p.y(), p.x()) = 255;
      }
    }
  }
  std::vector<double> offsets;
  for (const Frame& frame : frames) {
    LineFrame frame_lines = frontend.Process(frame.image);
    const SE3 cur_from_ref = frame.world_from_cam.Inverse() * keyframe.world_from_cam;
    std::vector<LineMatch> kept;
    wrong_matches->emplace_back(keyframe_lines.segments.size(), 0);
    for (const LineMatch& m : frontend.Match(&keyframe_lines, &frame_lines)) {
      const LineMatchTruth truth =
          JudgeLineMatchByDepth(camera, keyframe_lines.segments[m.ref_index], keyframe.depth,
                                cur_from_ref, frame_lines.segments[m.cur_index]);
      result->matches_correct += truth == LineMatchTruth::kCorrect;
      result->matches_wrong += truth == LineMatchTruth::kWrong;
      result->matches_unverifiable += truth == LineMatchTruth::kUnverifiable;
      wrong_matches->back()[m.ref_index] = truth == LineMatchTruth::kWrong;
      if (!config.drop_wrong_matches || truth != LineMatchTruth::kWrong) kept.push_back(m);
      // The detection error of a correct match's current segment: its line's distance from the
      // points at 1/4 and 3/4 of the exact segment (the points ExactCurrentSegment transfers).
      LineSegment exact;
      const LineSegment& detected = frame_lines.segments[m.cur_index];
      if (truth == LineMatchTruth::kCorrect &&
          ExactCurrentSegment(camera, keyframe.depth, cur_from_ref,
                              keyframe_lines.segments[m.ref_index], detected.octave,
                              config.lines.detector.endpoint_sigma_px, &exact)) {
        for (const double f : {0.25, 0.75}) {
          offsets.push_back(
              std::abs(detected.SignedDistance(exact.start + f * (exact.end - exact.start))));
        }
      }
    }
    std::vector<LineSegment> cur_segments = frame_lines.segments;
    if (config.exact_current_lines) {
      std::vector<LineMatch> transferred;
      for (const LineMatch& m : kept) {
        const LineSegment& ref = keyframe_lines.segments[m.ref_index];
        if (!ExactCurrentSegment(
                camera, keyframe.depth, cur_from_ref, ref, frame_lines.segments[m.cur_index].octave,
                config.lines.detector.endpoint_sigma_px, &cur_segments[m.cur_index])) {
          continue;
        }
        transferred.push_back(m);
      }
      kept = transferred;
    }
    lines->push_back(MatchedLinesFromMatches(kept, cur_segments,
                                             static_cast<int>(keyframe_lines.segments.size())));
  }
  result->current_offset_count = static_cast<int>(offsets.size());
  if (!offsets.empty()) {
    std::sort(offsets.begin(), offsets.end());
    result->current_offset_median_px = offsets[offsets.size() / 2];
    result->current_offset_p90_px = offsets[offsets.size() * 9 / 10];
  }
}

// The "line sigma px" cell of run v of `r` (run 0 is the photometric one).
std::string LineSigmaCell(const MapEvalResult& r, size_t v, double line_sigma_px) {
  if (v == 0) return "-";
  if (r.frontend_lines) return "frontend";
  char cell[32];
  std::snprintf(cell, sizeof(cell), "%.2f", line_sigma_px);
  return cell;
}

}  // namespace

MapEvalConfig::MapEvalConfig() {
  synth.preset = "textured";
  synth.width = 320;
  synth.height = 240;
  synth.fx = 262.5;
  synth.fy = 262.5;
  synth.frames = 0;  // set from keyframe_index, num_frames and frame_stride
  mapping.sigma_intensity = 1.0;
  mapping.sigma_epipolar_px = 0.1;
}

std::string MapEvalConfig::Check() const {
  if (keyframe_index < 0) return "keyframe_index must be >= 0";
  if (num_frames < 1) return "num_frames must be >= 1";
  if (frame_stride < 1) return "frame_stride must be >= 1";
  if (speed_repetitions < 0) return "speed_repetitions must be >= 0";
  if (line_sigma_px < 0.0) return "line_sigma_px must be >= 0";
  if (keyframe_line_sigma_px < 0.0) return "keyframe_line_sigma_px must be >= 0";
  if (frontend_lines && !line_sigma_sweep.empty()) {
    return "frontend_lines needs line_sigma_sweep=[] (the sweep perturbs GT lines)";
  }
  if (drop_wrong_matches && !frontend_lines) return "drop_wrong_matches needs frontend_lines";
  if (exact_current_lines && !frontend_lines) return "exact_current_lines needs frontend_lines";
  if (frontend_lines && keyframe_line_sigma_px > 0.0) {
    return "keyframe_line_sigma_px perturbs GT lines, which frontend_lines does not use";
  }
  const std::string lines_error = lines.Check();
  if (!lines_error.empty()) return "lines: " + lines_error;
  if (!(discontinuity_rel_step > 0.0)) return "discontinuity_rel_step must be > 0";
  if (discontinuity_radius_px < 0) return "discontinuity_radius_px must be >= 0";
  const std::string mapping_error = mapping.Check();
  if (!mapping_error.empty()) return "mapping: " + mapping_error;
  return "";
}

MapEvalResult RunMapEvaluation(const MapEvalConfig& config,
                               const RenderFrameFunction& render_frame) {
  const std::string error = config.Check();
  if (!error.empty()) throw std::invalid_argument("MapEvalConfig: " + error);
  synthetic::SynthOptions synth = config.synth;
  synth.frames = config.keyframe_index + config.num_frames * config.frame_stride + 1;
  const synthetic::SyntheticSequence sequence = synthetic::MakeSequence(synth);
  auto render = [&](int index) {
    const synthetic::RenderedFrame rendered = render_frame(sequence, index);
    return Frame{rendered.image, rendered.depth, sequence.ground_truth[index].world_from_cam};
  };
  const Frame keyframe = render(config.keyframe_index);
  std::vector<Frame> frames;
  for (int k = 1; k <= config.num_frames; ++k) {
    frames.push_back(render(config.keyframe_index + k * config.frame_stride));
  }
  GroundTruthEdgeOptions edge_options;
  edge_options.line_sigma_px = config.keyframe_line_sigma_px;
  edge_options.seed = static_cast<uint32_t>(config.line_seed);
  const GroundTruthEdges gt_edges = MakeGroundTruthEdges(
      synthetic_pairs::SegmentsInCam(sequence.scene, keyframe.world_from_cam.Inverse()),
      keyframe.depth, sequence.camera, edge_options);
  const PinholeCamera& camera = sequence.camera;
  const cv::Mat gt_idepth = InverseDepthFromDepth(keyframe.depth);
  KeyframeEdges edges;
  std::vector<std::vector<MatchedLine>> lines;   // of the main line-guided run
  std::vector<std::vector<char>> wrong_matches;  // frontend_lines
  MapEvalResult result;
  if (config.frontend_lines) {
    FrontendLines(config, keyframe, frames, gt_idepth,
                  ContinuousDepthMask(gt_idepth, config.discontinuity_radius_px,
                                      config.discontinuity_rel_step),
                  camera, &edges, &lines, &wrong_matches, &result);
  } else {
    edges = {gt_edges.trace, gt_edges.line_idepth, gt_edges.centre_mask};
    lines =
        GroundTruthLinesPerFrame(config, gt_edges, camera, keyframe, frames, config.line_sigma_px);
  }
  result.width = camera.width;
  result.height = camera.height;
  result.frontend_lines = config.frontend_lines;
  result.exact_current_lines = config.exact_current_lines;
  for (const TracedLine& line : edges.trace.lines) {
    result.num_edges += !line.pixels.empty();
    result.num_edge_pixels += static_cast<int>(line.pixels.size());
  }
  result.baseline_m =
      (frames.back().world_from_cam.translation() - keyframe.world_from_cam.translation()).norm();
  VariantState photometric_state, line_state;
  result.photometric = RunVariant(config, false, 0.0, camera, keyframe, frames, edges, lines, {},
                                  &photometric_state);
  result.line_guided = RunVariant(config, true, config.line_sigma_px, camera, keyframe, frames,
                                  edges, lines, wrong_matches, &line_state);
  const SemiDenseDepthMap& photometric_map = photometric_state.mapper->depth_map();
  const SemiDenseDepthMap& line_map = line_state.mapper->depth_map();
  const cv::Mat common = CommonEdgeMask(edges.mask, photometric_map, line_map);
  result.common_edges_photometric = EvaluateDepthMap(photometric_map, edges.idepth, common);
  result.common_edges_line = EvaluateDepthMap(line_map, edges.idepth, common);
  result.common_edges_photometric_line_regularized =
      EvaluateDepthMap(photometric_state.line_regularized, edges.idepth, common);
  result.common_edges_line_line_regularized =
      EvaluateDepthMap(line_state.line_regularized, edges.idepth, common);
  for (double sigma : config.line_sigma_sweep) {
    if (sigma < 0.0) throw std::invalid_argument("MapEvalConfig: line_sigma_sweep must be >= 0");
    result.line_sweep.push_back(
        RunVariant(config, true, sigma, camera, keyframe, frames, edges,
                   GroundTruthLinesPerFrame(config, gt_edges, camera, keyframe, frames, sigma)));
  }

  // Edge stereo speed with wide priors: one update of the random initialisation with the last
  // frame.
  if (config.speed_repetitions > 0) {
    const SE3 cur_from_ref = frames.back().world_from_cam.Inverse() * keyframe.world_from_cam;
    for (int variant = 0; variant < 2; ++variant) {
      MappingOptions options = config.mapping;
      options.use_line_stereo = variant == 1;
      double best = 1e30;
      for (int repetition = 0; repetition < config.speed_repetitions; ++repetition) {
        DepthMapper mapper(camera, options);
        mapper.InitializeKeyframe(keyframe.image, edges.trace);
        const FrameUpdateStats stats =
            mapper.UpdateWithFrame(frames.back().image, cur_from_ref, lines.back());
        if (stats.num_edge_pixels > 0) {
          best = std::min(best, 1e3 * stats.edge_stereo_ms / stats.num_edge_pixels);
        }
      }
      (variant == 0 ? result.wide_prior_photometric_us : result.wide_prior_line_us) = best;
    }
  }
  // The written maps and the propagation to the last frame: those of the run whose options are
  // config.mapping's (the line-guided one unless mapping.use_line_stereo is false).
  DepthMapper& mapper =
      config.mapping.use_line_stereo ? *line_state.mapper : *photometric_state.mapper;
  if (!config.out_dir.empty()) {
    std::filesystem::create_directories(config.out_dir);
    WriteInverseDepthPng(mapper.depth_map(), config.out_dir + "/keyframe_idepth.png");
    WriteInverseDepthPng(mapper.RegularizedMap(true, true),
                         config.out_dir + "/keyframe_idepth_regularized.png");
    WritePointCloudPly(mapper.RegularizedMap(true, true), keyframe.image, sequence.camera,
                       keyframe.world_from_cam, config.out_dir + "/keyframe_points.ply");
  }
  const Frame& last = frames.back();
  const GroundTruthEdges last_edges = MakeGroundTruthEdges(
      synthetic_pairs::SegmentsInCam(sequence.scene, last.world_from_cam.Inverse()), last.depth,
      sequence.camera, GroundTruthEdgeOptions());
  const PropagationStats propagation = mapper.PropagateToNewKeyframe(
      last.image, last_edges.trace, last.world_from_cam.Inverse() * keyframe.world_from_cam);
  result.propagated_count = propagation.propagated;
  result.propagated =
      EvaluateDepthMap(mapper.depth_map(), InverseDepthFromDepth(last.depth), cv::Mat());
  return result;
}

std::string FormatMapEvalTable(const MapEvalResult& r) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof(line),
                "mapeval: %dx%d, %d %s edges (%d traced pixels), keyframe-to-last baseline %.3f m\n"
                "rel. err = median |d - d_gt| / d_gt; NEES = (d - d_gt)^2 / V (consistent: mean 1, "
                "median 0.455, 95.4%% within 2 sigma)\n",
                r.width, r.height, r.num_edges, r.frontend_lines ? "frontend" : "GT",
                r.num_edge_pixels, r.baseline_m);
  out << line;
  if (r.frontend_lines) {
    std::snprintf(line, sizeof(line),
                  "frontend matches judged by the GT depth and poses: %d correct, %d wrong, %d "
                  "unverifiable (precision %.3f)\n",
                  r.matches_correct, r.matches_wrong, r.matches_unverifiable,
                  r.matches_correct / std::max(1.0, 1.0 * (r.matches_correct + r.matches_wrong)));
    out << line;
    std::snprintf(line, sizeof(line),
                  "current segments of the correct matches to their exact position (%d points at "
                  "1/4 and 3/4): median %.3f px, 90th percentile %.3f px\n",
                  r.current_offset_count, r.current_offset_median_px, r.current_offset_p90_px);
    out << line;
    if (r.exact_current_lines) {
      out << "current lines: the keyframe segments moved with the GT depth and poses "
             "(exact_current_lines)\n";
    }
  }
  out << "| stereo | line sigma px | hyp. | rel. err | mean NEES | median NEES | in 2 sigma | "
         "edge px | edge rel. err | edge mean NEES | edge median NEES | edge rel. err after 3D "
         "line reg. | its median NEES | smoothed rel. err | edge us/px | edge us/px frame 1 |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<const MapEvalRun*> runs = {&r.photometric, &r.line_guided};
  for (const MapEvalRun& run : r.line_sweep) runs.push_back(&run);
  for (size_t v = 0; v < runs.size(); ++v) {
    const MapEvalRun& run = *runs[v];
    const std::string sigma = LineSigmaCell(r, v, run.line_sigma_px);
    std::snprintf(line, sizeof(line),
                  "| %s | %s | %d | %.4f | %.2f | %.3f | %.3f | %d | %.4f | %.2f | %.3f | %.4f | "
                  "%.3f | %.4f | %.2f | %.2f |\n",
                  v == 0 ? "photometric" : "line-guided", sigma.c_str(), run.all.count,
                  run.all.median_rel_error, run.all.mean_nees, run.all.median_nees,
                  run.all.within_2sigma, run.edges.count, run.edges.median_rel_error,
                  run.edges.mean_nees, run.edges.median_nees,
                  run.edges_line_regularized.median_rel_error,
                  run.edges_line_regularized.median_nees, run.all_smoothed.median_rel_error,
                  run.edge_stereo_us_per_pixel, run.first_frame_edge_us_per_pixel);
    out << line;
  }
  out << "\nConsistency: gross = NEES > 10.83 (chi^2(1) 99.9%: 0.1% if consistent), bulk = mean "
         "NEES of the rest (0.988 if consistent); continuous = pixels away from GT depth "
         "discontinuities\n"
         "| stereo | line sigma px | all: mean NEES | gross | bulk | continuous px | mean NEES | "
         "median NEES | in 2 sigma | gross | bulk | edges: mean NEES | gross | bulk | after 3D "
         "line "
         "reg.: gross | bulk |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (size_t v = 0; v < runs.size(); ++v) {
    const MapEvalRun& run = *runs[v];
    const std::string sigma = LineSigmaCell(r, v, run.line_sigma_px);
    const DepthErrorStats& c = run.continuous;
    const DepthErrorStats& e = run.edges;
    const DepthErrorStats& l = run.edges_line_regularized;
    std::snprintf(line, sizeof(line),
                  "| %s | %s | %.2f | %.2f%% | %.3f | %d | %.2f | %.3f | %.3f | %.2f%% | %.3f | "
                  "%.2f | %.2f%% | %.3f | %.2f%% | %.3f |\n",
                  v == 0 ? "photometric" : "line-guided", sigma.c_str(), run.all.mean_nees,
                  100.0 * run.all.gross_fraction, run.all.bulk_mean_nees, c.count, c.mean_nees,
                  c.median_nees, c.within_2sigma, 100.0 * c.gross_fraction, c.bulk_mean_nees,
                  e.mean_nees, 100.0 * e.gross_fraction, e.bulk_mean_nees, 100.0 * l.gross_fraction,
                  l.bulk_mean_nees);
    out << line;
  }
  out << "\n";
  for (int v = 0; v < 2; ++v) {
    const MapEvalRun& run = *runs[v];
    std::snprintf(line, sizeof(line),
                  "%s: %d/%d candidates valid; line ok %d (SSD-refined %d), fallback %d, rejected "
                  "%d (%d out of range), matches dropped %d (%d of them wrong); ssd ok %d; EKF "
                  "outliers %d; 3D line reg: %d edges fitted, %d rejected, %d px updated, %d "
                  "outlier px\n",
                  v == 0 ? "photometric" : "line-guided", run.valid, run.candidates, run.line_ok,
                  run.line_refined, run.line_fallback, run.line_rejected, run.line_out_of_range,
                  run.line_matches_dropped, run.line_matches_dropped_wrong, run.ssd_ok,
                  run.outliers, run.line_stats.edges_fitted, run.line_stats.edges_rejected,
                  run.line_stats.pixels_updated, run.line_stats.pixels_rejected);
    out << line;
  }
  std::snprintf(line, sizeof(line),
                "edge pixels observed by both runs: %d; rel. err photometric %.4f, line-guided "
                "%.4f (mean NEES %.2f, %.2f); after 3D line reg. %.4f, %.4f\n",
                r.common_edges_photometric.count, r.common_edges_photometric.median_rel_error,
                r.common_edges_line.median_rel_error, r.common_edges_photometric.mean_nees,
                r.common_edges_line.mean_nees,
                r.common_edges_photometric_line_regularized.median_rel_error,
                r.common_edges_line_line_regularized.median_rel_error);
  out << line;
  if (r.wide_prior_photometric_us > 0.0) {
    std::snprintf(line, sizeof(line),
                  "edge stereo with wide priors (random init vs the last frame): photometric SSD "
                  "%.2f us/px, line-guided %.2f us/px\n",
                  r.wide_prior_photometric_us, r.wide_prior_line_us);
    out << line;
  }
  std::snprintf(line, sizeof(line),
                "propagated to the last frame: %d hypotheses, %d evaluated, rel. err %.4f, "
                "mean NEES %.2f, median NEES %.3f\n",
                r.propagated_count, r.propagated.count, r.propagated.median_rel_error,
                r.propagated.mean_nees, r.propagated.median_nees);
  out << line;
  return out.str();
}

}  // namespace pldvo
