// Every config shipped in experiments/configs/ loads into OdometryConfig and sets the switches
// its header comment names (a file that silently stopped doing what it says would otherwise run
// the defaults); every shipped file has its case here. docs/config_keys.md and _backend.md hold the
// key table of `pldvo run --list_config` (DescribeConfig), split in two, and must equal it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "backend/odometry/odometry_config.h"
#include "core/config_io.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;

const fs::path kConfigDir = fs::path(PLDVO_SOURCE_DIR) / "experiments" / "configs";

OdometryConfig Load(const std::string& name) {
  OdometryConfig config;
  LoadConfigYaml((kConfigDir / (name + ".yaml")).string(), &config);
  EXPECT_EQ(config.Check(), "") << name;
  return config;
}

using Policy = WeightingPolicy;
using Method = LineDetectorOptions::Method;
using RegMethod = MappingOptions::LineRegularizationMethod;

// The mapping and odometry switches that every points-and-lines config (all but sdvo) turns on.
void ExpectLinesInMappingAndTracking(const OdometryConfig& config, const std::string& name) {
  EXPECT_TRUE(config.odometry.use_lines) << name;
  EXPECT_TRUE(config.mapping.use_line_stereo) << name;
}

// This implementation's extras, each on (points_lines and its ablations) or off (paper).
void ExpectExtras(const OdometryConfig& config, bool on, const std::string& name) {
  SCOPED_TRACE(name + (on ? ": extras on" : ": extras off"));
  EXPECT_EQ(config.lines.detector.method, on ? Method::kEdLines : Method::kLsd);
  EXPECT_EQ(config.lines.detector.num_octaves, 2);
  EXPECT_EQ(config.lines.detector.endpoint_sigma_px, on ? 0.5 : 1.0);
  EXPECT_EQ(config.lines.merger.max_segments, on ? 150 : 0);
  EXPECT_EQ(config.mapping.stereo_error_correlation, on ? 0.1 : 0.0);
  EXPECT_EQ(config.mapping.residual_intensity_noise, on);
  EXPECT_EQ(config.mapping.ssd_ambiguity_variance, on);
  EXPECT_EQ(config.mapping.line_stereo_check_ssd, on);
  EXPECT_EQ(config.mapping.line_stereo_keyframe_line_var, on);
  EXPECT_EQ(config.mapping.line_stereo_estimated_line_noise, on);
  EXPECT_EQ(config.mapping.line_stereo_ssd, on ? MappingOptions::LineStereoSsd::kRefineMorePrecise
                                               : MappingOptions::LineStereoSsd::kFallback);
  // Off in every config: the paper's behaviour paid on the development set.
  EXPECT_FALSE(config.mapping.line_stereo_prior_interval);
  EXPECT_EQ(config.mapping.line_stereo_min_interval_px, 0.0);
  EXPECT_EQ(config.tracking.problem.weighting.line_noise, NoiseSource::kFixed);
  // The paper's 3D line regularisation is one of the things the default leaves out.
  EXPECT_EQ(config.mapping.line_regularization, !on);
  EXPECT_EQ(config.mapping.line_regularization_method,
            on ? RegMethod::kRay1d : RegMethod::kPaper2d);
  EXPECT_EQ(config.mapping.max_reference_points, on ? 4000 : 0);
  EXPECT_EQ(config.odometry.predict_line_matches, on);
  EXPECT_EQ(config.odometry.line_prior_gate_px, on ? 2.0 : 0.0);
  EXPECT_EQ(config.odometry.line_outlier_px, on ? 2.0 : 0.0);
  EXPECT_EQ(config.odometry.try_alternatives, on);
  if (on) {
    EXPECT_EQ(config.odometry.alternative_choice,
              OdometryOptions::AlternativeChoice::kMotionGatedInlierRows);
  }
  EXPECT_EQ(config.odometry.two_view_bootstrap, on);
  if (on) {
    EXPECT_EQ(config.odometry.two_view_min_inliers, 30);
  }
  EXPECT_EQ(config.odometry.line_consensus_max_cost_drop, on ? 8.4 : 0.0);
  EXPECT_EQ(config.odometry.random_map_warmup_updates, on ? 3 : 0);
  EXPECT_EQ(config.odometry.random_start_candidates, on ? 5 : 1);
  EXPECT_EQ(config.tracking.problem.weighting.intensity_noise,
            on ? NoiseSource::kEstimated : NoiseSource::kFixed);
  EXPECT_EQ(config.keyframes.max_rms_growth, on ? 1.5 : 0.0);
  EXPECT_EQ(config.tracking.problem.max_rows_per_edge, on ? 50.0 : 0.0);
}

// Per shipped file: what its header comment says it turns on.
const std::map<std::string, std::function<void(const OdometryConfig&)>>& Cases() {
  static const std::map<std::string, std::function<void(const OdometryConfig&)>> cases = {
      {"paper",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kCovariance);
         ExpectLinesInMappingAndTracking(c, "paper");
         ExpectExtras(c, false, "paper");
       }},
      {"points_lines",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kCovariance);
         ExpectLinesInMappingAndTracking(c, "points_lines");
         ExpectExtras(c, true, "points_lines");
         EXPECT_FALSE(c.backend.edge_ba.enabled);
         EXPECT_FALSE(c.backend.windowed_ba.enabled);
         EXPECT_EQ(c.keyframes.max_relative_distance, 0.1);
       }},
      {"points_lines_edge_ba",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kCovariance);
         ExpectLinesInMappingAndTracking(c, "points_lines_edge_ba");
         ExpectExtras(c, true, "points_lines_edge_ba");
         EXPECT_TRUE(c.backend.edge_ba.enabled);
         EXPECT_EQ(c.backend.edge_ba.window, 5);
         EXPECT_EQ(c.backend.edge_ba.max_iterations, 20);
         EXPECT_EQ(c.backend.edge_ba.lines_leaving_window, EdgeBALeavingLines::kFree);
       }},
      {"points_lines_ba",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kCovariance);
         ExpectLinesInMappingAndTracking(c, "points_lines_ba");
         ExpectExtras(c, true, "points_lines_ba");
         EXPECT_FALSE(c.backend.edge_ba.enabled);
         EXPECT_TRUE(c.backend.windowed_ba.enabled);
         EXPECT_EQ(c.backend.windowed_ba.window, 10);
         EXPECT_EQ(c.backend.windowed_ba.max_points, 2000);
         EXPECT_EQ(c.backend.windowed_ba.max_iterations, 20);
         EXPECT_TRUE(c.backend.windowed_ba.lines);
         EXPECT_EQ(c.backend.windowed_ba.interpolation, ImageInterpolation::kBicubic);
         EXPECT_EQ(c.keyframes.max_relative_distance, 0.03);  // points_lines: 0.1
       }},
      {"sdvo",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kPhotometricOnly);
         EXPECT_FALSE(c.odometry.use_lines);
         EXPECT_FALSE(c.mapping.use_line_stereo);
         EXPECT_FALSE(c.mapping.line_regularization);
         EXPECT_TRUE(c.odometry.two_view_bootstrap);
         EXPECT_EQ(c.odometry.two_view_min_inliers, 50);  // points_lines: 30
         EXPECT_EQ(c.tracking.problem.weighting.intensity_noise, NoiseSource::kFixed);
         EXPECT_EQ(c.keyframes.max_rms_growth, 0.0);
       }},
      {"lines_only",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kLineOnly);
         ExpectLinesInMappingAndTracking(c, "lines_only");
         EXPECT_FALSE(c.mapping.line_regularization);
       }},
      {"uniform_weights",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kUniform);
         ExpectLinesInMappingAndTracking(c, "uniform_weights");
         ExpectExtras(c, true, "uniform_weights");
       }},
      {"fixed_ratio",
       [](const OdometryConfig& c) {
         EXPECT_EQ(c.tracking.problem.weighting.policy, Policy::kFixedRatio);
         EXPECT_EQ(c.tracking.problem.weighting.fixed_ratio_lambda, 1.0);
         ExpectLinesInMappingAndTracking(c, "fixed_ratio");
         EXPECT_FALSE(c.mapping.line_regularization);
       }},
  };
  return cases;
}

TEST(ShippedConfigsTest, EachConfigSetsTheSwitchesItsCommentNames) {
  for (const auto& [name, expect] : Cases()) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(fs::exists(kConfigDir / (name + ".yaml")));
    OdometryConfig config;
    ASSERT_NO_THROW(config = Load(name));
    expect(config);
  }
}

// A new config file needs its case above.
TEST(ShippedConfigsTest, EveryShippedConfigHasACase) {
  std::set<std::string> shipped;
  for (const fs::directory_entry& entry : fs::directory_iterator(kConfigDir)) {
    if (entry.path().extension() == ".yaml") shipped.insert(entry.path().stem().string());
  }
  std::set<std::string> tested;
  for (const auto& name_case : Cases()) tested.insert(name_case.first);
  EXPECT_EQ(shipped, tested);
}

// The default config is points_lines (its file names no key whose value differs), and paper
// differs from it exactly in the extras.
TEST(ShippedConfigsTest, DefaultsArePointsLinesAndPaperSwitchesOffTheExtras) {
  ExpectExtras(OdometryConfig(), true, "defaults");
  EXPECT_EQ(ConfigToString(Load("points_lines")), ConfigToString(OdometryConfig()));
}

// The key table of a docs page: from its header row "| key | type | default | doc |" on.
std::string KeyTable(const std::string& page) {
  std::ifstream file(fs::path(PLDVO_SOURCE_DIR) / "docs" / page);
  EXPECT_TRUE(file) << "docs/" << page << " missing";
  std::stringstream text;
  text << file.rdbuf();
  const std::string doc = text.str();
  const size_t table = doc.find("| key | type | default | doc |");
  EXPECT_NE(table, std::string::npos) << "no key table in docs/" << page;
  return table == std::string::npos ? std::string() : doc.substr(table);
}

// docs/config_keys.md and docs/config_keys_backend.md: each a header, then the two halves of the
// table `pldvo run --list_config` prints, the second half under its own two header rows
// (regenerate with scripts/config_keys.sh).
TEST(ConfigKeysDocTest, EqualsTheListConfigTable) {
  const std::string first = KeyTable("config_keys.md");
  const std::string second = KeyTable("config_keys_backend.md");
  const size_t rows = second.find('\n', second.find('\n') + 1);  // after the two header rows
  ASSERT_NE(rows, std::string::npos);
  EXPECT_EQ(first + second.substr(rows + 1), DescribeConfig(OdometryConfig()))
      << "docs/config_keys.md or docs/config_keys_backend.md is stale: run scripts/config_keys.sh";
  EXPECT_EQ(second.find("| **`odometry`** | section"), rows + 1)
      << "docs/config_keys_backend.md must start at the odometry section";
}

}  // namespace
}  // namespace pldvo
