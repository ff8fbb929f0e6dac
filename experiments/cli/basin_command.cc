// `pldvo basin`: the convergence basin of direct tracking, photometric-only vs points and lines
// (docs/tracking.md, "Convergence basin").
//
// Renders a synthetic sequence, picks frame pairs with gaps spread evenly from min_gap to
// max_gap (reference frames spread over the sequence), builds the reference of each pair from
// its GT depth, tracks the later frame from the identity pose with photometric_only, line_only
// and covariance (points and lines) weighting, and counts a pair as converged when the estimate
// is within translation_threshold and rotation_threshold of the ground truth. Prints a Markdown
// table per gap bin and the accuracy at gaps <= 10. The line matches (basin.lines):
//   ground_truth  the scene's 3D edges projected with the GT poses (exact lines, points sampled
//                 on the edges; the `reference` options);
//   frontend      the odometry's: the line frontend's segments of both images matched without a
//                 prediction, every keyframe segment traced, the mapping's semi-dense selection
//                 with GT depth (DepthMapper::InitializeKeyframeFromDepth) and
//                 mapping.max_reference_points per level (foot points with
//                 mapping.edge_foot_points, as in MappingWorker); each match judged by
//                 JudgeLineMatchByDepth, and with drop_wrong_matches the wrong ones left out.
//   pldvo basin                                    # lowtex, 60 pairs, gaps 1..40, 320x240
//   pldvo basin --set basin.preset=textured --set tracking.solver=ceres
//   pldvo basin --set basin.lines=frontend [--set basin.drop_wrong_matches=true]
#include <gflags/gflags.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/mapping_options.h"
#include "backend/odometry/reference_builder.h"
#include "backend/tracking/tracker.h"
#include "core/config_io.h"
#include "core/statistics.h"
#include "core/wall_clock.h"
#include "experiments/cli/command.h"
#include "experiments/evaluation/line_match_ground_truth.h"
#include "experiments/evaluation/synthetic_pairs.h"
#include "frontend/line_frontend.h"

DEFINE_string(basin_csv, "", "Optional CSV file with one row per pair and mode.");
DEFINE_bool(basin_list_options, false, "Print every --set key with its default, then exit.");

namespace pldvo {
namespace {

struct BasinOptions {
  std::string preset = "lowtex";
  int seed = 1;
  int frames = 300;
  int width = 320;
  int height = 240;
  int pairs = 60;
  int min_gap = 1;
  int max_gap = 40;
  double translation_threshold = 0.01;  // m
  double rotation_threshold = 0.5;      // deg
  std::string lines = "ground_truth";
  bool drop_wrong_matches = false;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("preset", &preset, "Synthetic preset: textured | lowtex | lighting | fast.");
    v.Field("seed", &seed, "Seed of the synthetic sequence.");
    v.Field("frames", &frames, "Length of the sequence (30 fps).");
    v.Field("width", &width, "Image width (focal length scaled from 525 px at 640).");
    v.Field("height", &height, "Image height.");
    v.Field("pairs", &pairs, "Number of frame pairs.");
    v.Field("min_gap", &min_gap, "Smallest frame gap of a pair.");
    v.Field("max_gap", &max_gap, "Largest frame gap of a pair.");
    v.Field("translation_threshold", &translation_threshold,
            "Converged when the translation error is below this (m)...");
    v.Field("rotation_threshold", &rotation_threshold,
            "...and the rotation error below this (deg).");
    v.Field("lines", &lines,
            "Line matches and reference: ground_truth (GT edges, exact lines) | frontend (the "
            "line frontend's matches, the mapping's GT-depth keyframe map, as the odometry).");
    v.Field("drop_wrong_matches", &drop_wrong_matches,
            "frontend: leave out the matches the GT depth judges wrong (an oracle matcher).");
  }
  std::string Check() const {
    if (pairs < 1 || min_gap < 1 || max_gap < min_gap || frames <= max_gap + 1) {
      return "need pairs >= 1, 1 <= min_gap <= max_gap < frames - 1";
    }
    if (lines != "ground_truth" && lines != "frontend") {
      return "lines must be ground_truth or frontend, not '" + lines + "'";
    }
    if (drop_wrong_matches && lines != "frontend") return "drop_wrong_matches needs lines=frontend";
    return "";
  }
};

struct BasinConfig {
  BasinOptions basin;
  TrackingOptions tracking;
  GroundTruthReferenceOptions reference;
  LineFrontendOptions lines;
  MappingOptions mapping;
  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Section("basin", &basin, "Pairs and convergence thresholds.");
    v.Section("tracking", &tracking, "Tracker options (the policy is set per mode).");
    v.Section("reference", &reference,
              "Reference construction (lines=frontend uses num_levels and idepth_var).");
    v.Section("lines", &lines, "Line frontend (lines=frontend).");
    v.Section("mapping", &mapping,
              "Semi-dense selection and reference budget of the GT-depth map (lines=frontend).");
  }
  std::string Check() const {
    std::string error = basin.Check();
    if (error.empty()) error = tracking.Check();
    if (error.empty()) error = reference.Check();
    if (error.empty()) error = lines.Check();
    if (error.empty()) error = mapping.Check();
    return error;
  }
};

struct MatchCounts {
  int correct = 0, wrong = 0, unverifiable = 0;
};

// basin.lines = frontend: the reference the odometry would track a pair against if its keyframe
// map were the GT depth (header comment); counts the judged matches.
TrackingReference FrontendPairReference(const synthetic_pairs::FramePair& pair,
                                        const BasinConfig& config, LineFrontend* frontend,
                                        MatchCounts* counts) {
  LineFrame keyframe = frontend->Process(pair.ref_image);
  LineFrame frame = frontend->Process(pair.cur_image);
  std::vector<LineMatch> all(keyframe.segments.size());
  for (size_t i = 0; i < all.size(); ++i) all[i].ref_index = static_cast<int>(i);
  const EdgeTrace edges = frontend->TraceMatched(keyframe, all);
  std::vector<LineMatch> kept;
  for (const LineMatch& m : frontend->Match(&keyframe, &frame)) {
    const LineMatchTruth truth =
        JudgeLineMatchByDepth(pair.camera, keyframe.segments[m.ref_index], pair.ref_depth,
                              pair.cur_from_ref, frame.segments[m.cur_index]);
    counts->correct += truth == LineMatchTruth::kCorrect;
    counts->wrong += truth == LineMatchTruth::kWrong;
    counts->unverifiable += truth == LineMatchTruth::kUnverifiable;
    if (!config.basin.drop_wrong_matches || truth != LineMatchTruth::kWrong) kept.push_back(m);
  }
  DepthMapper mapper(pair.camera, config.mapping);
  mapper.InitializeKeyframeFromDepth(pair.ref_image, edges, pair.ref_depth,
                                     config.reference.idepth_var);
  TrackingReference reference = BuildReferencePoints(
      mapper.depth_map(), ImagePyramid(pair.ref_image, config.reference.num_levels), pair.camera,
      config.mapping.max_reference_points,
      config.mapping.edge_foot_points ? mapper.keyframe_lines() : std::vector<Eigen::Vector3d>());
  SetMatchedLines(
      MatchedLinesFromMatches(kept, frame.segments, static_cast<int>(keyframe.segments.size())),
      &reference);
  return reference;
}

struct Mode {
  const char* name;
  WeightingPolicy policy;
};
const Mode kModes[] = {{"photometric", WeightingPolicy::kPhotometricOnly},
                       {"lines", WeightingPolicy::kLineOnly},
                       {"points+lines", WeightingPolicy::kCovariance}};
constexpr int kNumModes = 3;

struct Bin {
  int lo, hi;
};
const Bin kBins[] = {{1, 5}, {6, 10}, {11, 20}, {21, 30}, {31, 40}};

int RunBasin(const CommandContext& context) {
  try {
    BasinConfig config;
    if (FLAGS_basin_list_options) {
      std::cout << DescribeConfig(config);
      return 0;
    }
    ApplyOverrides(context.config_overrides, &config);
    CheckOptionsOrThrow(config, "basin config");
    const BasinOptions& basin = config.basin;
    const synthetic::SyntheticSequence sequence = synthetic_pairs::MakeScaledSequence(
        basin.preset, basin.frames, basin.seed, basin.width, basin.height);

    std::vector<Tracker> trackers;
    for (const Mode& mode : kModes) {
      TrackingOptions options = config.tracking;
      options.problem.weighting.policy = mode.policy;
      trackers.emplace_back(options);
    }

    std::ofstream csv;
    if (!FLAGS_basin_csv.empty()) {
      csv.open(FLAGS_basin_csv);
      if (!csv) throw std::runtime_error("cannot write " + FLAGS_basin_csv);
      csv << "ref,cur,gap,gt_translation_m,gt_rotation_deg,mode,translation_error_m,"
             "rotation_error_deg,converged,status,iterations,milliseconds\n";
    }

    struct Row {
      int gap;
      double gt_translation, gt_rotation;
      bool converged[kNumModes];
      double translation_error[kNumModes], rotation_error[kNumModes];
    };
    const bool frontend_lines = basin.lines == "frontend";
    LineFrontend frontend(config.lines);
    MatchCounts counts;
    std::vector<Row> rows;
    double milliseconds[kNumModes] = {0, 0, 0};
    for (int k = 0; k < basin.pairs; ++k) {
      const int gap =
          basin.pairs == 1
              ? basin.min_gap
              : basin.min_gap + static_cast<int>(std::lround(static_cast<double>(k) *
                                                             (basin.max_gap - basin.min_gap) /
                                                             (basin.pairs - 1)));
      // Reference frames spread over the sequence (a stride coprime to typical lengths).
      const int ref = (k * 97) % (basin.frames - gap);
      const synthetic_pairs::FramePair pair =
          synthetic_pairs::MakeFramePair(sequence, ref, ref + gap);
      const TrackingReference reference =
          frontend_lines
              ? FrontendPairReference(pair, config, &frontend, &counts)
              : synthetic_pairs::MakePairReference(pair, config.reference, /*with_edges=*/true);
      const ImagePyramid current(pair.cur_image, config.reference.num_levels);
      Row row;
      row.gap = gap;
      row.gt_translation = pair.cur_from_ref.translation().norm();
      row.gt_rotation = LogSO3(pair.cur_from_ref.rotation_matrix()).norm() * 180.0 / M_PI;
      for (int m = 0; m < kNumModes; ++m) {
        const auto start = WallClock::now();
        const TrackingResult result = trackers[m].Track(reference, current, SE3());
        const double ms = MsSince(start);
        milliseconds[m] += ms;
        const double t_error =
            synthetic_pairs::TranslationError(result.cur_from_ref, pair.cur_from_ref);
        const double r_error =
            synthetic_pairs::RotationErrorDeg(result.cur_from_ref, pair.cur_from_ref);
        row.converged[m] =
            t_error < basin.translation_threshold && r_error < basin.rotation_threshold;
        row.translation_error[m] = t_error;
        row.rotation_error[m] = r_error;
        if (csv) {
          csv << ref << "," << ref + gap << "," << gap << "," << row.gt_translation << ","
              << row.gt_rotation << "," << kModes[m].name << "," << t_error << "," << r_error << ","
              << row.converged[m] << "," << TrackingStatusName(result.status) << ","
              << result.TotalIterations() << "," << ms << "\n";
        }
      }
      rows.push_back(row);
      std::fprintf(stderr, "\rpair %d/%d", k + 1, basin.pairs);
    }
    std::fprintf(stderr, "\n");

    std::printf(
        "Convergence basin: preset %s, seed %d, %dx%d, %d pairs, solver %s, lines %s%s; "
        "converged = error < %.3g m and < %.3g deg from GT, tracking from identity.\n",
        basin.preset.c_str(), basin.seed, basin.width, basin.height, basin.pairs,
        config.tracking.solver.type == SolverOptions::Type::kCeres ? "ceres" : "gauss_newton",
        basin.lines.c_str(), basin.drop_wrong_matches ? " (wrong matches dropped)" : "",
        basin.translation_threshold, basin.rotation_threshold);
    if (frontend_lines) {
      std::printf("Matches judged by depth: %d correct, %d wrong, %d unverifiable.\n",
                  counts.correct, counts.wrong, counts.unverifiable);
    }
    std::printf("\n");
    std::printf("| gap (frames) | pairs | mean GT motion | photometric | lines | points+lines |\n");
    std::printf("| --- | --- | --- | --- | --- | --- |\n");
    auto print_row = [&](const std::string& label, int lo, int hi) {
      int count = 0;
      int converged[kNumModes] = {0, 0, 0};
      double translation = 0.0, rotation = 0.0;
      for (const Row& row : rows) {
        if (row.gap < lo || row.gap > hi) continue;
        ++count;
        translation += row.gt_translation;
        rotation += row.gt_rotation;
        for (int m = 0; m < kNumModes; ++m) converged[m] += row.converged[m];
      }
      if (count == 0) return;
      std::printf("| %s | %d | %.1f cm, %.1f deg |", label.c_str(), count,
                  100.0 * translation / count, rotation / count);
      for (int m = 0; m < kNumModes; ++m) {
        std::printf(" %d/%d (%.0f%%) |", converged[m], count, 100.0 * converged[m] / count);
      }
      std::printf("\n");
    };
    for (const Bin& bin : kBins) {
      print_row(std::to_string(bin.lo) + "-" + std::to_string(bin.hi), bin.lo, bin.hi);
    }
    print_row("all", 0, 1 << 30);

    // Accuracy at the small gaps, over every pair (converged or not).
    constexpr int kAccuracyMaxGap = 10;
    std::printf(
        "\nAccuracy over the pairs with gap <= %d, every pair: translation error mean / median "
        "(mm), rotation error mean / median (deg):\n\n",
        kAccuracyMaxGap);
    std::printf("| mode | pairs | translation mm | rotation deg |\n| --- | --- | --- | --- |\n");
    for (int m = 0; m < kNumModes; ++m) {
      std::vector<double> translation, rotation;
      for (const Row& row : rows) {
        if (row.gap > kAccuracyMaxGap) continue;
        translation.push_back(1000.0 * row.translation_error[m]);
        rotation.push_back(row.rotation_error[m]);
      }
      std::printf("| %s | %zu | %.3f / %.3f | %.4f / %.4f |\n", kModes[m].name, translation.size(),
                  Mean(translation), Median(translation), Mean(rotation), Median(rotation));
    }
    std::printf("\nMean tracking time per pair:");
    for (int m = 0; m < kNumModes; ++m) {
      std::printf(" %s %.1f ms;", kModes[m].name, milliseconds[m] / basin.pairs);
    }
    std::printf("\n");
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "pldvo basin: " << error.what() << "\n";
    return 1;
  }
}

PLDVO_REGISTER_COMMAND("basin",
                       "Convergence basin of tracking: photometric-only vs points and lines.",
                       RunBasin);

}  // namespace
}  // namespace pldvo
