// Semi-dense mapping on a small synthetic sequence (160x120, 8 frames, textured preset, GT poses)
// through experiments/evaluation/mapping_evaluation.h: convergence from a random initialisation,
// line-guided vs photometric stereo on edge pixels, the 3D line regularisation, NEES and
// propagation; line matches outside the prior interval. Measured values at this config (pldvo
// mapeval with the same --set keys) are quoted next to each tolerance; the tolerances leave ~2x
// margin on them and sit far from what a broken stage gives (the random initialisation has a median
// relative error of ~60%). The TESTs reading Result() or TexturedSeed2Result() share one
// evaluation: ctest runs this binary as one process (ONE_PROCESS, tests/CMakeLists.txt), and the
// evaluations of one sequence render its frames once (the render cache).
#include "backend/mapping/depth_mapper.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "experiments/evaluation/mapping_evaluation.h"
#include "experiments/evaluation/synthetic_pairs.h"
#include "tests/render_cache.h"

namespace pldvo {
namespace {

// The line-guided stereo of eqs. 8-10 on its own, the mechanism most TESTs here measure; the SSD
// refinement of its matches (the default, refine_more_precise) is compared with it in
// SsdSearchModesOnMatchedEdgesAtOnePixelLineNoise.
constexpr MappingOptions::LineStereoSsd kLineStereoAlone = MappingOptions::LineStereoSsd::kFallback;

MapEvalConfig SmallConfig() {
  MapEvalConfig config;
  config.synth.width = 160;
  config.synth.height = 120;
  config.synth.fx = 131.25;
  config.synth.fy = 131.25;
  config.synth.threads = 2;
  config.num_frames = 8;
  config.frame_stride = 3;
  config.line_sigma_px = 0.25;
  config.line_sigma_sweep = {0.1};
  config.speed_repetitions = 0;  // timing belongs in `pldvo mapeval`, not in a test
  config.mapping.line_stereo_ssd = kLineStereoAlone;
  return config;
}

// `pldvo mapeval --set synth.preset=P --set synth.seed=S --set line_sigma_sweep=[]` (320x240).
MapEvalConfig SequenceConfig(const std::string& preset, int seed) {
  MapEvalConfig config;
  config.synth.preset = preset;
  config.synth.seed = seed;
  config.synth.threads = 2;
  config.line_sigma_sweep = {};
  config.speed_repetitions = 0;
  config.mapping.line_stereo_ssd = kLineStereoAlone;
  return config;
}

MapEvalResult Evaluate(const MapEvalConfig& config) {
  return RunMapEvaluation(config, test::RenderFrameForTest);
}

const MapEvalResult& Result() {
  static const MapEvalResult result = Evaluate(SmallConfig());
  return result;
}

// The default config on textured seed 2, the reference of two TESTs.
const MapEvalResult& TexturedSeed2Result() {
  static const MapEvalResult result = Evaluate(SequenceConfig("textured", 2));
  return result;
}

TEST(DepthMapperTest, ConvergesFromRandomInitialisation) {
  const MapEvalResult& r = Result();
  // Measured: 0.032 median relative error over ~7800 hypotheses (of 8342 candidates).
  EXPECT_GT(r.photometric.all.count, 5000);
  EXPECT_LT(r.photometric.all.median_rel_error, 0.07);
  EXPECT_LT(r.line_guided.all.median_rel_error, 0.07);
}

TEST(DepthMapperTest, LineGuidedAtLeastAsAccurateOnEdges) {
  const MapEvalResult& r = Result();
  ASSERT_GT(r.photometric.edges.count, 500);
  ASSERT_GT(r.line_guided.edges.count, 500);
  ASSERT_EQ(r.line_sweep.size(), 1u);
  // With sub-pixel lines (endpoint sigma 0.1 px) the line-guided edge depth is clearly better
  // (measured 0.006 vs 0.028); at 0.25 px it is still better here (0.016 vs 0.028) but the
  // crossover is near 0.25-0.5 px (docs/mapping.md), so only the 0.1 px run is held to <=.
  EXPECT_LE(r.line_sweep[0].edges.median_rel_error, r.photometric.edges.median_rel_error);
  EXPECT_LT(r.line_guided.edges.median_rel_error, 0.06);
}

TEST(DepthMapperTest, LineRegularizationReducesEdgeError) {
  const MapEvalResult& r = Result();
  // Measured: photometric 0.028 -> 0.012, line-guided 0.016 -> 0.013.
  EXPECT_LT(r.photometric.edges_line_regularized.median_rel_error,
            r.photometric.edges.median_rel_error);
  EXPECT_LT(r.line_guided.edges_line_regularized.median_rel_error,
            r.line_guided.edges.median_rel_error);
  EXPECT_GT(r.photometric.line_stats.edges_fitted, 20);
}

TEST(DepthMapperTest, SsdSearchModesOnMatchedEdgesAtOnePixelLineNoise) {
  // mapping.line_stereo_ssd at 1 px endpoint noise, where the plain line-guided match (fallback)
  // is worse than the SSD search. refine (the SSD search within +- 2 sigma_lambda of the line's
  // match) keeps the line's disambiguation and the SSD's localisation; refine_more_precise
  // replaces the line's match only where refine would and the SSD's variance is also the
  // smaller: fewer replacements; first searches the whole prior interval before the line: the
  // SSD takes edge pixels the line took, and the edges get about the SSD search's accuracy; fuse
  // averages where refine replaces.
  // Measured (edge median relative error after the 3D line regularisation): fallback 0.0371,
  // refine 0.0111, photometric 0.0115; replacements refine 12426, refine_more_precise 11751;
  // first: line-guided matches 18284 -> 3187, SSD matches 24096 -> 46746, edge error 0.0102.
  MapEvalConfig config = SmallConfig();
  config.line_sigma_px = 1.0;
  config.line_sigma_sweep = {};
  const MapEvalResult fallback = Evaluate(config);
  config.mapping.line_stereo_ssd = MappingOptions::LineStereoSsd::kRefine;
  const MapEvalResult refine = Evaluate(config);
  config.mapping.line_stereo_ssd = MappingOptions::LineStereoSsd::kRefineMorePrecise;
  const MapEvalResult more_precise = Evaluate(config);
  config.mapping.line_stereo_ssd = MappingOptions::LineStereoSsd::kFuse;
  const MapEvalResult fuse = Evaluate(config);
  config.mapping.line_stereo_ssd = MappingOptions::LineStereoSsd::kFirst;
  const MapEvalResult first = Evaluate(config);
  auto edge_error = [](const MapEvalRun& run) {
    return run.edges_line_regularized.median_rel_error;
  };
  const double photometric_error = edge_error(refine.photometric);
  EXPECT_EQ(fallback.line_guided.line_refined, 0);
  EXPECT_GT(refine.line_guided.line_refined, 1000);
  EXPECT_LT(edge_error(refine.line_guided), 0.5 * edge_error(fallback.line_guided));
  EXPECT_LT(edge_error(refine.line_guided), 1.2 * photometric_error);
  EXPECT_GT(more_precise.line_guided.line_refined, 0);
  EXPECT_LT(more_precise.line_guided.line_refined, refine.line_guided.line_refined);
  EXPECT_GT(fuse.line_guided.line_refined, 1000);
  EXPECT_LT(edge_error(fuse.line_guided), 0.5 * edge_error(fallback.line_guided));
  EXPECT_LT(first.line_guided.line_ok, fallback.line_guided.line_ok / 2);
  EXPECT_GT(first.line_guided.ssd_ok, fallback.line_guided.ssd_ok);
  EXPECT_LT(edge_error(first.line_guided), 1.2 * photometric_error);
}

TEST(DepthMapperTest, FusedLineAndSsdMatchesHaveTheirPredictedVariance) {
  // Two measurements of one inverse depth, the line's with a part every frame shares (the keyframe
  // edge) and an independent part, the SSD's independent: the fused estimate's Monte Carlo
  // variance and its covariance with the line's shared error match FuseObservations' prediction.
  StereoObservation line, ssd;
  line.idepth_var = 4e-4;
  line.shared_idepth_var = 1e-4;
  line.disparity_var = 0.4;
  ssd.idepth_var = 1e-4;
  ssd.disparity_var = 0.1;
  std::mt19937 rng(5);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double truth = 0.5;
  const int n = 200000;
  double sum = 0.0, sum_sq = 0.0, sum_shared = 0.0;
  StereoObservation fused;
  for (int i = 0; i < n; ++i) {
    const double shared = std::sqrt(line.shared_idepth_var) * unit(rng);
    line.idepth = truth + shared + std::sqrt(line.idepth_var - line.shared_idepth_var) * unit(rng);
    ssd.idepth = truth + std::sqrt(ssd.idepth_var) * unit(rng);
    fused = FuseObservations(line, ssd);
    sum += fused.idepth - truth;
    sum_sq += (fused.idepth - truth) * (fused.idepth - truth);
    sum_shared += (fused.idepth - truth) * shared;
  }
  EXPECT_DOUBLE_EQ(fused.idepth_var, 1.0 / (1.0 / 4e-4 + 1.0 / 1e-4));
  EXPECT_DOUBLE_EQ(fused.disparity_var, 0.08);
  EXPECT_NEAR(sum / n, 0.0, 1e-4);
  EXPECT_NEAR(sum_sq / n / fused.idepth_var, 1.0, 0.02);
  // Cov(fused, shared) = w_line Var(shared) = sqrt(shared_idepth_var * Var(shared)) here.
  EXPECT_NEAR(sum_shared / n / std::sqrt(fused.shared_idepth_var * line.shared_idepth_var), 1.0,
              0.03);
}

TEST(DepthMapperTest, NeesInSaneBand) {
  const MapEvalResult& r = Result();
  // The error distribution is heavy-tailed (depth discontinuities, wrong matches), so the mean
  // NEES (~200) is dominated by a few percent of outliers; the bulk is checked through the median
  // NEES (0.455 for a consistent Gaussian filter; measured 1.01 photometric, 0.65 line-guided) and
  // the fraction within 2 sigma (0.954 if consistent; measured 0.68-0.75). A factor 10 either
  // way of the median would mean a wrong variance model.
  for (const MapEvalRun* run : {&r.photometric, &r.line_guided}) {
    EXPECT_GT(run->all.median_nees, 0.455 / 10.0);
    EXPECT_LT(run->all.median_nees, 0.455 * 10.0);
    EXPECT_GT(run->all.within_2sigma, 0.5);
  }
  // Line-guided edge pixels: measured median NEES 0.36 (consistent within the same factor).
  EXPECT_GT(r.line_guided.edges.median_nees, 0.455 / 10.0);
  EXPECT_LT(r.line_guided.edges.median_nees, 0.455 * 10.0);
}

TEST(DepthMapperTest, BulkNeesIsConsistentAwayFromDiscontinuities) {
  const MapEvalResult& r = Result();
  // The mean NEES split at the chi^2(1) 99.9% quantile: the bulk's mean is 0.988 for a consistent
  // filter. Measured on pixels away from GT depth discontinuities: photometric 0.93, line-guided
  // 0.80 (gross errors 17% / 14%, against 0.1% if the tails were Gaussian: not a bound the model
  // meets, so only a regression bound here); line-guided edge pixels: bulk 0.99, gross 1.0%.
  for (const MapEvalRun* run : {&r.photometric, &r.line_guided}) {
    EXPECT_GT(run->continuous.count, 2000);
    EXPECT_GT(run->continuous.bulk_mean_nees, 0.5);
    EXPECT_LT(run->continuous.bulk_mean_nees, 2.0);
    EXPECT_LT(run->continuous.gross_fraction, 0.35);
  }
  EXPECT_GT(r.line_guided.edges.bulk_mean_nees, 0.5);
  EXPECT_LT(r.line_guided.edges.bulk_mean_nees, 2.5);
  EXPECT_LT(r.line_guided.edges.gross_fraction, 0.05);
}

TEST(DepthMapperTest, CorrelatedFusionReducesGrossErrorsOnLowTexture) {
  // The correlated-error fusion (mapping.stereo_error_correlation, SemiDenseDepthMap::Fuse)
  // against the independent-error EKF on `pldvo mapeval --set synth.preset=lowtex --set
  // synth.seed=2` (320x240, 15 frames), pixels away from GT depth discontinuities. Measured
  // (independent -> correlated, rho = 0.1): gross fraction (NEES > 10.83) photometric 19.1% ->
  // 10.6%, line-guided 3.7% -> 3.1%; bulk mean NEES 2.32 -> 1.94 and 1.73 -> 1.19; mean NEES of
  // all hypotheses 485 -> 298 and 168 -> 125; median relative error of all hypotheses 0.0105 ->
  // 0.0102 and 0.0093 -> 0.0087. Required: the gross fraction below 0.7x (photometric, measured
  // 0.55x) and 0.95x (line-guided, 0.84x), the all-pixel mean NEES below 0.85x (0.61x, 0.74x),
  // the bulk within [0.5, 2.5], and no accuracy lost (5% slack on the relative error). Two
  // mapeval runs, ~3 s. The remaining gross
  // pixels are mostly wrong matches (docs/mapping.md), which no variance model makes consistent.
  MapEvalConfig config = SequenceConfig("lowtex", 2);
  ASSERT_GT(config.mapping.stereo_error_correlation, 0.0);  // the default is the new model
  const MapEvalResult correlated = Evaluate(config);
  config.mapping.stereo_error_correlation = 0.0;
  const MapEvalResult independent = Evaluate(config);
  const std::pair<const MapEvalRun*, const MapEvalRun*> runs[] = {
      {&correlated.photometric, &independent.photometric},
      {&correlated.line_guided, &independent.line_guided}};
  const double max_gross_ratio[] = {0.7, 0.95};
  for (int v = 0; v < 2; ++v) {
    const MapEvalRun& with = *runs[v].first;
    const MapEvalRun& without = *runs[v].second;
    ASSERT_GT(with.continuous.count, 3000);
    EXPECT_LT(with.continuous.gross_fraction,
              max_gross_ratio[v] * without.continuous.gross_fraction);
    EXPECT_LT(with.all.mean_nees, 0.85 * without.all.mean_nees);
    EXPECT_GT(with.continuous.bulk_mean_nees, 0.5);
    EXPECT_LT(with.continuous.bulk_mean_nees, 2.5);
    EXPECT_LT(with.all.median_rel_error, 1.05 * without.all.median_rel_error);
  }
}

// For photometric and line-guided stereo, on the pixels away from GT depth discontinuities:
// `with` has under nees_factor the mean NEES of `without`, under gross_factor its gross fraction,
// and a relative error of all hypotheses below rel_error_factor times that of `without`.
void ExpectShrunkenTail(const MapEvalResult& with_result, const MapEvalResult& without_result,
                        double nees_factor, double gross_factor, double rel_error_factor) {
  const std::pair<const MapEvalRun*, const MapEvalRun*> runs[] = {
      {&with_result.photometric, &without_result.photometric},
      {&with_result.line_guided, &without_result.line_guided}};
  for (const auto& [with, without] : runs) {
    ASSERT_GT(with->continuous.count, 10000);
    EXPECT_LT(with->continuous.mean_nees, nees_factor * without->continuous.mean_nees);
    EXPECT_LT(with->continuous.gross_fraction, gross_factor * without->continuous.gross_fraction);
    EXPECT_LT(with->all.median_rel_error, rel_error_factor * without->all.median_rel_error);
  }
}

TEST(DepthMapperTest, HalfPixelStepsAndAmbiguityVarianceShrinkTheTextureTail) {
  // The SSD search at half-pixel steps with the ambiguity variance (the defaults) against Engel's
  // 1-px steps without it, on `pldvo mapeval --set synth.preset=textured --set synth.seed=2`,
  // pixels away from GT depth discontinuities. Measured (1-px -> defaults): mean NEES
  // photometric 30.40 -> 9.17, line-guided 28.19 -> 6.44; gross fraction 2.51% -> 1.17% and
  // 2.70% -> 1.42%; median relative error 0.0038 -> 0.0035 and 0.0042 -> 0.0039. Required: the
  // mean NEES below 0.5x, the gross fraction below 0.7x, no accuracy lost (2% slack).
  MapEvalConfig config = SequenceConfig("textured", 2);
  ASSERT_EQ(config.mapping.ssd_search_step_px, 0.5);
  ASSERT_TRUE(config.mapping.ssd_ambiguity_variance);
  const MapEvalResult& half = TexturedSeed2Result();
  config.mapping.ssd_search_step_px = 1.0;
  config.mapping.ssd_ambiguity_variance = false;
  const MapEvalResult one = Evaluate(config);
  ExpectShrunkenTail(half, one, /*nees_factor=*/0.5, /*gross_factor=*/0.7,
                     /*rel_error_factor=*/1.02);
}

TEST(DepthMapperTest, InlierRatioFilterShrinksTheTextureTail) {
  // The Gaussian x uniform inlier-ratio filter (mapping.outlier_model=inlier_ratio) against the
  // validity counter (the default), on `pldvo mapeval --set synth.preset=textured --set
  // synth.seed=2`, pixels away from GT depth discontinuities. Measured (validity counter ->
  // inlier ratio): mean NEES photometric 7.51 -> 4.62, line-guided 5.30 -> 3.35; gross fraction
  // 1.12% -> 0.95% and 1.40% -> 1.25%; median relative error of all hypotheses 0.0035 and 0.0039
  // both. Required: the mean NEES below 0.75x, the gross fraction below 0.95x, no accuracy lost
  // (2% slack). Measured with line-guided matches outside the prior interval dropped; with them
  // fused (the default) the line-guided gross fraction is 1.82% -> 1.74% (0.96x).
  MapEvalConfig config = SequenceConfig("textured", 2);
  ASSERT_EQ(config.mapping.outlier_model, MappingOptions::OutlierModel::kValidityCounter);
  config.mapping.line_stereo_prior_interval = true;
  const MapEvalResult counter = Evaluate(config);
  config.mapping.outlier_model = MappingOptions::OutlierModel::kInlierRatio;
  const MapEvalResult ratio = Evaluate(config);
  ExpectShrunkenTail(ratio, counter, /*nees_factor=*/0.75, /*gross_factor=*/0.95,
                     /*rel_error_factor=*/1.02);
}

TEST(DepthMapperTest, KeyframeLineVarianceKeepsNoisyEdgesConsistent) {
  // Keyframe lines with the frontend's endpoint noise (0.5 px, like the current lines): the same
  // keyframe error enters every line-guided observation of a pixel. `pldvo mapeval --set
  // synth.preset=lowtex --set synth.seed=2 --set line_sigma_sweep=[] --set line_sigma_px=0.5
  // --set keyframe_line_sigma_px=0.5 [--set mapping.line_stereo_keyframe_line_var=false]`,
  // line-guided edge pixels, without -> with the keyframe line's shared variance: gross fraction
  // 15.83% -> 0.08%, bulk mean NEES 2.61 -> 0.91, median relative error 0.0281 -> 0.0206.
  MapEvalConfig config = SequenceConfig("lowtex", 2);
  config.line_sigma_px = 0.5;
  config.keyframe_line_sigma_px = 0.5;
  ASSERT_TRUE(config.mapping.line_stereo_keyframe_line_var);
  const MapEvalResult with = Evaluate(config);
  config.mapping.line_stereo_keyframe_line_var = false;
  const MapEvalResult without = Evaluate(config);
  const DepthErrorStats& a = with.line_guided.edges;
  const DepthErrorStats& b = without.line_guided.edges;
  ASSERT_GT(a.count, 3000);
  EXPECT_GT(b.gross_fraction, 0.05);
  EXPECT_LT(a.gross_fraction, 0.2 * b.gross_fraction);
  EXPECT_GT(a.bulk_mean_nees, 0.5);
  EXPECT_LT(a.bulk_mean_nees, 2.0);
  EXPECT_LT(a.median_rel_error, b.median_rel_error);
}

TEST(DepthMapperTest, FrontendLinesGuideTheStereoOnLowTexture) {
  // The keyframe's edges and the line matches from the line frontend instead of GT, GT poses:
  // `pldvo mapeval --set synth.preset=lowtex --set synth.seed=2 --set line_sigma_sweep=[] --set
  // frontend_lines=true`. Measured: 45 edges, edge median relative error photometric 0.0067,
  // line-guided 0.0053; on the 1175 edge pixels both runs observed 0.0067 and 0.0050; line-guided
  // continuous mean NEES 0.78, edge gross fraction 0.46%; the correct matches' current segments
  // lie a median 0.094 px (90th percentile 0.713 px) from their exact position.
  MapEvalConfig config = SequenceConfig("lowtex", 2);
  config.frontend_lines = true;
  const MapEvalResult r = Evaluate(config);
  EXPECT_TRUE(r.frontend_lines);
  EXPECT_GT(r.num_edges, 20);
  ASSERT_GT(r.line_guided.edges.count, 500);
  EXPECT_GT(r.line_guided.line_ok, 10000);
  EXPECT_LT(r.line_guided.edges.median_rel_error, r.photometric.edges.median_rel_error);
  // The same on the pixels both runs observed: a subset of each run's own edge pixels.
  ASSERT_GT(r.common_edges_line.count, 500);
  EXPECT_EQ(r.common_edges_line.count, r.common_edges_photometric.count);
  EXPECT_LE(r.common_edges_line.count,
            std::min(r.line_guided.edges.count, r.photometric.edges.count));
  EXPECT_LT(r.common_edges_line.median_rel_error, r.common_edges_photometric.median_rel_error);
  EXPECT_LT(r.line_guided.continuous.mean_nees, 1.5);
  EXPECT_LT(r.line_guided.edges.gross_fraction, 0.02);
  ASSERT_GT(r.current_offset_count, 500);
  EXPECT_GT(r.current_offset_median_px, 0.0);
  EXPECT_LT(r.current_offset_median_px, 0.25);
  EXPECT_LT(r.current_offset_p90_px, 1.5);
  // The sweep and the keyframe line noise perturb GT lines, which this mode does not have.
  config.keyframe_line_sigma_px = 0.5;
  EXPECT_THROW(Evaluate(config), std::invalid_argument);
  config.keyframe_line_sigma_px = 0.0;
  config.line_sigma_sweep = {0.5};
  EXPECT_THROW(Evaluate(config), std::invalid_argument);
}

TEST(DepthMapperTest, WrongFrontendMatchesAreTheTexturedEdgeTail) {
  // The frontend's matches on textured judged by the GT depth and poses (JudgeLineMatchByDepth),
  // and the same mapping with the wrong ones left out (an oracle matcher): `pldvo mapeval --set
  // synth.seed=2 --set line_sigma_sweep=[] --set frontend_lines=true [--set
  // drop_wrong_matches=true]`. Measured: 916 correct, 103 wrong, 27 unverifiable (precision
  // 0.899); line-guided edge gross fraction 4.82% -> 0.84%, edge mean NEES 55.9 -> 6.1. The
  // bounds (more than 4% wrong, the oracle at most 0.6x) hold for the sanitizers' 8 frames too.
  MapEvalConfig config = SequenceConfig("textured", 2);
  config.frontend_lines = true;
#ifdef PLDVO_SANITIZE
  // CI budget under the sanitizers (docs/reliability.md): 8 frames instead of 15. Measured: 604
  // correct, 38 wrong; edge gross fraction 2.95% -> 1.34%, edge mean NEES 20.30 -> 8.78.
  config.num_frames = 8;
#endif
  const MapEvalResult with_wrong = Evaluate(config);
  config.drop_wrong_matches = true;
  const MapEvalResult oracle = Evaluate(config);
  EXPECT_EQ(oracle.matches_wrong, with_wrong.matches_wrong);
  ASSERT_GT(with_wrong.matches_correct, 500);
  EXPECT_GT(with_wrong.matches_wrong, 0.04 * with_wrong.matches_correct);
  ASSERT_GT(oracle.line_guided.edges.count, 2000);
  EXPECT_GT(with_wrong.line_guided.edges.gross_fraction, 0.02);
  EXPECT_LT(oracle.line_guided.edges.gross_fraction,
            0.6 * with_wrong.line_guided.edges.gross_fraction);
  EXPECT_LT(oracle.line_guided.edges.mean_nees, 0.6 * with_wrong.line_guided.edges.mean_nees);
  // The photometric run does not use the matches.
  EXPECT_EQ(oracle.photometric.edges.median_rel_error,
            with_wrong.photometric.edges.median_rel_error);
  config.frontend_lines = false;
  EXPECT_THROW(Evaluate(config), std::invalid_argument);
}

TEST(DepthMapperTest, ExactCurrentLinesMakeTheTexturedEdgesMoreAccurate) {
  // Issue 6's edge claim on textured fails with the frontend's lines, and not because of its
  // wrong matches (previous test). With every current segment replaced by its keyframe segment
  // moved with the GT depth and pose (exact_current_lines: the current detection error removed,
  // the keyframe segment's kept) the line-guided edges beat the SSD search: `pldvo mapeval --set
  // synth.seed=2 --set line_sigma_sweep=[] --set frontend_lines=true [--set
  // exact_current_lines=true]`. Measured: edge rel. error 0.0036 (frontend) -> 0.0016 (exact),
  // photometric 0.0024.
  MapEvalConfig config = SequenceConfig("textured", 2);
  config.frontend_lines = true;
#ifdef PLDVO_SANITIZE
  // CI budget under the sanitizers (docs/reliability.md): 5 frames instead of 15. Measured:
  // 0.0141 -> 0.0029, photometric 0.0060.
  config.num_frames = 5;
#endif
  const MapEvalResult frontend = Evaluate(config);
  config.exact_current_lines = true;
  const MapEvalResult exact = Evaluate(config);
  ASSERT_GT(exact.line_guided.edges.count, 2000);
  std::printf("edge rel. error: photometric %.4f, frontend lines %.4f, exact current lines %.4f\n",
              exact.photometric.edges.median_rel_error, frontend.line_guided.edges.median_rel_error,
              exact.line_guided.edges.median_rel_error);
  EXPECT_LT(exact.line_guided.edges.median_rel_error,
            0.85 * exact.photometric.edges.median_rel_error);
  EXPECT_LT(exact.line_guided.edges.median_rel_error,
            0.7 * frontend.line_guided.edges.median_rel_error);
  config.frontend_lines = false;
  EXPECT_THROW(Evaluate(config), std::invalid_argument);
}

// The keyframe of the two wrong-match tests below: frame 0 of a small textured sequence from its
// GT depth (traced pixels hold the depth of their 3D line, as line-guided stereo leaves them),
// its GT edges, frame 10 with the exact GT lines of its pose, and `wrong`, the matched edge with
// the most traced pixels (the one a test moves).
struct WrongMatchCase {
  PinholeCamera camera;
  cv::Mat keyframe_image;
  cv::Mat image;
  SE3 cur_from_ref;
  GroundTruthEdges edges;
  cv::Mat depth;
  std::vector<MatchedLine> lines;
  int wrong = -1;
  size_t wrong_pixels = 0;
};

WrongMatchCase MakeWrongMatchCase() {
  const synthetic::SyntheticSequence sequence =
      synthetic_pairs::MakeScaledSequence("textured", 11, 1, 320, 240);
  WrongMatchCase c;
  c.camera = sequence.camera;
  const synthetic::RenderedFrame keyframe = test::RenderFrameForTest(sequence, 0);
  c.keyframe_image = keyframe.image;
  c.image = test::RenderFrameForTest(sequence, 10).image;
  const SE3& world_from_ref = sequence.ground_truth[0].world_from_cam;
  c.cur_from_ref = sequence.ground_truth[10].world_from_cam.Inverse() * world_from_ref;
  c.edges =
      MakeGroundTruthEdges(synthetic_pairs::SegmentsInCam(sequence.scene, world_from_ref.Inverse()),
                           keyframe.depth, c.camera, GroundTruthEdgeOptions());
  c.depth = keyframe.depth.clone();
  for (int y = 0; y < c.depth.rows; ++y) {
    for (int x = 0; x < c.depth.cols; ++x) {
      const float line_idepth = c.edges.line_idepth.at<float>(y, x);
      if (line_idepth > 0.f) c.depth.at<float>(y, x) = 1.f / line_idepth;
    }
  }
  c.lines = ProjectGroundTruthLines(c.edges, c.camera, c.cur_from_ref, 0.0, 1);
  for (const TracedLine& line : c.edges.trace.lines) {
    if (line.id < static_cast<int>(c.lines.size()) && c.lines[line.id].matched &&
        line.pixels.size() > c.wrong_pixels) {
      c.wrong_pixels = line.pixels.size();
      c.wrong = line.id;
    }
  }
  return c;
}

TEST(DepthMapperTest, LineMatchContradictedByTheMapIsLeftOut) {
  // A keyframe from its GT depth (sigma 0.01 per metre; traced pixels hold the depth of their 3D
  // line, as line-guided stereo leaves them), its GT edges and the exact GT lines of frame 10, but
  // one edge's line moved 6 px along its normal (a wrong match, like a neighbouring texture line).
  // Its intersections leave every pixel's prior interval, so with
  // line_match_max_outside_fraction 0.8 that match alone is left out; off (1), none is.
  WrongMatchCase c = MakeWrongMatchCase();
  const PinholeCamera& camera = c.camera;
  const cv::Mat& image = c.image;
  const SE3& cur_from_ref = c.cur_from_ref;
  const GroundTruthEdges& edges = c.edges;
  const cv::Mat& depth = c.depth;
  std::vector<MatchedLine>& lines = c.lines;
  const int wrong = c.wrong;
  ASSERT_GE(wrong, 0);
  ASSERT_GT(c.wrong_pixels, 50u);
  lines[wrong].line_in_cur.line.z() -= 6.0;  // l = (a, b, c) with a^2 + b^2 = 1
  for (double fraction : {0.5, 1.0}) {
    MappingOptions options;
    options.line_stereo_ssd = kLineStereoAlone;
    options.line_match_max_outside_fraction = fraction;
    DepthMapper mapper(camera, options);
    mapper.InitializeKeyframeFromDepth(c.keyframe_image, edges.trace, depth, 1e-4);
    const FrameUpdateStats stats = mapper.UpdateWithFrame(image, cur_from_ref, lines);
    EXPECT_GT(stats.line_ok, 1000);
    if (fraction < 1.0) {
      EXPECT_EQ(stats.dropped_line_matches, std::vector<int>{wrong});
    } else {
      EXPECT_TRUE(stats.dropped_line_matches.empty());
    }
  }
}

// mapping.line_stereo_prior_interval: the keyframe, frame and wrong match of the test above, with
// the line moved 2 px (6 px puts the intersections outside the global inverse-depth bounds, 0.5
// px inside the EKF gate) and without the SSD check on line matches (which would see the shifted
// match first). On (default) the wrong edge's intersections fall outside the pixels' prior
// intervals and are dropped; off (the paper) only the global bounds apply, so they reach the
// fusion, whose 2-sigma gate rejects every one of them. Measured: 569 of the edge's 569 pixels
// either way, at shifts of 1-3 px.
TEST(DepthMapperTest, LineMatchesOutsideThePriorIntervalAreDroppedOrLeftToTheGate) {
  WrongMatchCase c = MakeWrongMatchCase();
  const PinholeCamera& camera = c.camera;
  const cv::Mat& image = c.image;
  const SE3& cur_from_ref = c.cur_from_ref;
  const GroundTruthEdges& edges = c.edges;
  const cv::Mat& depth = c.depth;
  std::vector<MatchedLine>& lines = c.lines;
  const int wrong = c.wrong;
  ASSERT_GE(wrong, 0);
  ASSERT_GT(c.wrong_pixels, 50u);
  lines[wrong].line_in_cur.line.z() -= 2.0;
  FrameUpdateStats stats[2];
  for (const bool prior_interval : {false, true}) {
    MappingOptions options;
    options.line_stereo_ssd = kLineStereoAlone;
    options.line_stereo_check_ssd = false;
    options.line_stereo_prior_interval = prior_interval;
    DepthMapper mapper(camera, options);
    mapper.InitializeKeyframeFromDepth(c.keyframe_image, edges.trace, depth, 1e-4);
    stats[prior_interval] = mapper.UpdateWithFrame(image, cur_from_ref, lines);
  }
  const FrameUpdateStats& on = stats[1];
  const FrameUpdateStats& off = stats[0];
  const int most = static_cast<int>(c.wrong_pixels);
  // 90%: a few of the edge's pixels may lack a hypothesis or leave the image.
  EXPECT_GT(on.line_out_of_range, 0.9 * most);
  EXPECT_EQ(off.line_out_of_range, 0);
  EXPECT_GT(off.line_ok, on.line_ok + 0.9 * most);
  EXPECT_GT(off.outliers, on.outliers + 0.9 * most);
  EXPECT_EQ(off.fused, on.fused);  // the gate kept the wrong observations out of the map
}

// UpdateWithFrame's line_cov_scale (mapping.line_stereo_estimated_line_noise: s^2 of the line
// noise the tracked frame implies) multiplies the current lines' Sigma_l2 in eq. 10. Keyframe
// from its GT depth (sigma 0.01 per metre) and the exact GT lines of frame 10, one of them moved
// 2 px (its pixels are left out of the count): at s^2 = 16 the same line-guided matches are
// made and every hypothesis they update keeps more of its variance (measured: 9279 of the 9280
// correct edges' matches; one pixel's observation was gated out either way).
TEST(DepthMapperTest, LineCovarianceScaleWidensTheLineGuidedObservations) {
  WrongMatchCase c = MakeWrongMatchCase();
  ASSERT_GE(c.wrong, 0);
  c.lines[c.wrong].line_in_cur.line.z() -= 2.0;
  MappingOptions options;
  options.line_stereo_check_ssd = false;
  FrameUpdateStats stats[2];
  std::vector<float> variances[2];
  for (const int scaled : {0, 1}) {
    DepthMapper mapper(c.camera, options);
    mapper.InitializeKeyframeFromDepth(c.keyframe_image, c.edges.trace, c.depth, 1e-4);
    stats[scaled] = mapper.UpdateWithFrame(c.image, c.cur_from_ref, c.lines, Matrix6d::Zero(),
                                           scaled ? 16.0 : 1.0);
    const SemiDenseDepthMap& map = mapper.depth_map();
    for (int i = 0; i < map.num_pixels(); ++i) {
      variances[scaled].push_back(map.valid(i) && map.edge_id(i) >= 0 && map.edge_id(i) != c.wrong
                                      ? map.idepth_var(i)
                                      : 0.f);
    }
  }
  EXPECT_EQ(stats[1].line_ok, stats[0].line_ok);
  int wider = 0, narrower = 0;
  for (size_t i = 0; i < variances[0].size(); ++i) {
    wider += variances[1][i] > variances[0][i];
    narrower += variances[1][i] < variances[0][i];
  }
  EXPECT_GT(wider, 0.9 * (stats[0].line_ok - static_cast<int>(c.wrong_pixels)));
  EXPECT_EQ(narrower, 0);
  EXPECT_THROW(DepthMapper(c.camera, options)
                   .UpdateWithFrame(c.image, c.cur_from_ref, c.lines, Matrix6d::Zero(), 0.0),
               std::invalid_argument);
}

TEST(DepthMapperTest, NarrowPriorsAreSearchedByTheSsdAndUnobservedOnesByTheLine) {
  // mapping.line_stereo_min_interval_px: an observed hypothesis whose prior interval spans less
  // than that on the epipolar line is refined by the SSD instead of the line-guided stereo; a
  // hypothesis without observations (the random start) keeps the line.
  const WrongMatchCase c = MakeWrongMatchCase();
  FrameUpdateStats from_depth[4];
  const double thresholds[4] = {0.0, 1e6, 0.5, 1.0};
  for (int k = 0; k < 4; ++k) {
    MappingOptions options;
    options.line_stereo_min_interval_px = thresholds[k];
    DepthMapper mapper(c.camera, options);
    // Inverse-depth sigma 0.01: +- 2 sigma spans 0.5-1 px of the epipolar line in this pair.
    mapper.InitializeKeyframeFromDepth(c.keyframe_image, c.edges.trace, c.depth, 1e-4);
    from_depth[k] = mapper.UpdateWithFrame(c.image, c.cur_from_ref, c.lines);
  }
  ASSERT_GT(from_depth[0].line_attempts, 1000);
  EXPECT_EQ(from_depth[0].line_narrow_prior, 0);
  // Every matched edge pixel is narrower than 1e6 px: none goes to the line, all to the SSD.
  EXPECT_EQ(from_depth[1].line_attempts, 0);
  EXPECT_EQ(from_depth[1].line_narrow_prior, from_depth[0].line_attempts);
  EXPECT_GT(from_depth[1].ssd_attempts, from_depth[0].ssd_attempts);
  // The threshold is in pixels of the interval: all are wider than 0.5 px, none than 1 px.
  EXPECT_EQ(from_depth[2].line_narrow_prior, 0);
  EXPECT_EQ(from_depth[2].line_attempts, from_depth[0].line_attempts);
  EXPECT_EQ(from_depth[3].line_narrow_prior, from_depth[0].line_attempts);

  MappingOptions options;
  options.line_stereo_min_interval_px = 1e6;
  DepthMapper random_start(c.camera, options);
  random_start.InitializeKeyframe(c.keyframe_image, c.edges.trace);
  const FrameUpdateStats first = random_start.UpdateWithFrame(c.image, c.cur_from_ref, c.lines);
  EXPECT_GT(first.line_attempts, 1000);
  EXPECT_EQ(first.line_narrow_prior, 0);
  options.line_stereo_min_interval_px = -1.0;
  EXPECT_THROW(DepthMapper(c.camera, options), std::invalid_argument);
}

TEST(DepthMapperTest, TheStereoPassDoesNotDependOnItsThreads) {
  // mapping.num_threads runs the stereo pass in stripes on OpenCV's thread pool; every pixel's
  // search and fusion is its own, so the map and the counters are the same bit for bit. Two
  // updates of the keyframe's depth with a wrong line match left to the EKF gate (the test above)
  // exercise fusion and the outlier gate.
  WrongMatchCase c = MakeWrongMatchCase();
  ASSERT_GE(c.wrong, 0);
  c.lines[c.wrong].line_in_cur.line.z() -= 2.0;
  std::vector<SemiDenseDepthMap> maps;
  std::vector<FrameUpdateStats> stats;
  for (const int threads : {1, 3}) {
    MappingOptions options;
    options.num_threads = threads;
    options.line_stereo_check_ssd = false;
    options.line_stereo_prior_interval = false;
    DepthMapper mapper(c.camera, options);
    mapper.InitializeKeyframeFromDepth(c.keyframe_image, c.edges.trace, c.depth, 1e-4);
    mapper.UpdateWithFrame(c.image, c.cur_from_ref, c.lines);
    stats.push_back(mapper.UpdateWithFrame(c.image, c.cur_from_ref, c.lines));
    maps.push_back(mapper.depth_map());
  }
  EXPECT_GT(stats[0].fused, 1000);
  EXPECT_GT(stats[0].line_ok, 1000);
  EXPECT_GT(stats[0].outliers, 0);
  for (const auto& count :
       {&FrameUpdateStats::line_attempts, &FrameUpdateStats::line_ok,
        &FrameUpdateStats::line_rejected, &FrameUpdateStats::ssd_attempts,
        &FrameUpdateStats::ssd_ok, &FrameUpdateStats::fused, &FrameUpdateStats::created,
        &FrameUpdateStats::outliers, &FrameUpdateStats::num_edge_pixels}) {
    EXPECT_EQ(stats[1].*count, stats[0].*count);
  }
  int differing = 0;
  for (int i = 0; i < maps[0].num_pixels(); ++i) {
    differing += maps[0].valid(i) != maps[1].valid(i) || maps[0].idepth(i) != maps[1].idepth(i) ||
                 maps[0].idepth_var(i) != maps[1].idepth_var(i) ||
                 maps[0].validity(i) != maps[1].validity(i) ||
                 maps[0].blacklist(i) != maps[1].blacklist(i);
  }
  EXPECT_EQ(differing, 0);
}

TEST(DepthMapperTest, PropagationKeepsAccuracy) {
  const MapEvalResult& r = Result();
  // Measured: 5082 hypotheses propagated, median relative error 0.0118 against the new
  // keyframe's GT depth.
  EXPECT_GT(r.propagated.count, 2000);
  EXPECT_LT(r.propagated.median_rel_error, 0.05);
}

}  // namespace
}  // namespace pldvo
