#include "core/config_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace pldvo {
namespace {

// A test-only options tree: two levels of sections, an enum, every field type.
struct SolverOptions {
  enum class Kind { kCeres, kGaussNewton, kLevenbergMarquardt };
  Kind kind = Kind::kCeres;
  int max_iterations = 20;
  double tolerance = 1e-6;
  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Choice("kind", &kind,
             {{"ceres", Kind::kCeres},
              {"gauss_newton", Kind::kGaussNewton},
              {"levenberg_marquardt", Kind::kLevenbergMarquardt}},
             "Which solver runs the tracking problem.");
    v.Field("max_iterations", &max_iterations, "Iterations per pyramid level.");
    v.Field("tolerance", &tolerance, "Relative cost change that stops the solver.");
  }
  bool operator==(const SolverOptions& o) const {
    return kind == o.kind && max_iterations == o.max_iterations && tolerance == o.tolerance;
  }
};

struct TrackingOptions {
  bool use_lines = true;
  std::vector<double> level_weights = {1.0, 0.5};
  SolverOptions solver;
  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("use_lines", &use_lines, "Add the point-to-line residuals.");
    v.Field("level_weights", &level_weights, "Weight per pyramid level | finest first.");
    v.Section("solver", &solver, "The nonlinear least-squares solver.");
  }
  bool operator==(const TrackingOptions& o) const {
    return use_lines == o.use_lines && level_weights == o.level_weights && solver == o.solver;
  }
};

struct TestOptions {
  std::string name = "default";
  double scale = 1.5;
  TrackingOptions tracking;
  int seed = 42;
  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("name", &name, "Run name.");
    v.Field("scale", &scale, "Scale factor.");
    v.Section("tracking", &tracking, "Frame-to-keyframe tracking.");
    v.Field("seed", &seed, "Random seed.");
  }
  std::string Check() const {
    return tracking.solver.max_iterations > 0 ? "" : "tracking.solver.max_iterations must be > 0";
  }
  bool operator==(const TestOptions& o) const {
    return name == o.name && (scale == o.scale || (std::isnan(scale) && std::isnan(o.scale))) &&
           tracking == o.tracking && seed == o.seed;
  }
};

std::string WriteFile(const std::string& name, const std::string& content) {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string path = ::testing::TempDir() + "pldvo_config_io_" + info->name() + "_" + name;
  std::ofstream(path) << content;
  return path;
}

std::string LoadError(const std::string& content) {
  const std::string path = WriteFile("bad.yaml", content);
  TestOptions options;
  try {
    LoadConfigYaml(path, &options);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "no exception";
}

std::string OverrideError(const std::vector<std::string>& overrides) {
  TestOptions options;
  try {
    ApplyOverrides(overrides, &options);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "no exception";
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "'"

TEST(ConfigIoTest, EmptyFileKeepsDefaults) {
  TestOptions options;
  LoadConfigYaml(WriteFile("empty.yaml", ""), &options);
  EXPECT_TRUE(options == TestOptions());
  LoadConfigYaml(WriteFile("header_only.yaml", "%YAML:1.0\n---\n"), &options);
  EXPECT_TRUE(options == TestOptions());
}

TEST(ConfigIoTest, LoadSetsNestedValuesAndKeepsMissingDefaults) {
  const std::string path = WriteFile("good.yaml",
                                     "name: \"run 7\"\n"
                                     "tracking:\n"
                                     "  use_lines: false\n"
                                     "  level_weights: [2, 0.25, 0.125]\n"
                                     "  solver:\n"
                                     "    kind: gauss_newton\n"
                                     "    tolerance: 1e-8\n"
                                     "seed: 7\n");
  TestOptions options;
  LoadConfigYaml(path, &options);
  TestOptions expected;
  expected.name = "run 7";
  expected.tracking.use_lines = false;
  expected.tracking.level_weights = {2.0, 0.25, 0.125};
  expected.tracking.solver.kind = SolverOptions::Kind::kGaussNewton;
  expected.tracking.solver.tolerance = 1e-8;
  expected.seed = 7;
  EXPECT_TRUE(options == expected);
  EXPECT_EQ(options.scale, 1.5);                          // absent: default
  EXPECT_EQ(options.tracking.solver.max_iterations, 20);  // absent: default
}

TEST(ConfigIoTest, UnknownKeyNamesTheFileAndTheDottedKey) {
  const std::string content = "tracking:\n  solver:\n    max_iteration: 5\n";
  const std::string message = LoadError(content);
  EXPECT_CONTAINS(message, "pldvo_config_io_");
  EXPECT_CONTAINS(message, "'tracking.solver.max_iteration'");
  EXPECT_CONTAINS(message, "did you mean 'tracking.solver.max_iterations'");
  EXPECT_CONTAINS(LoadError("tracking:\n  solvr: {}\n"), "'tracking.solvr'");
  EXPECT_CONTAINS(LoadError("tracking:\n  solvr: {}\n"), "did you mean 'tracking.solver'");
  EXPECT_CONTAINS(LoadError("seeds: 3\n"), "'seeds'");
}

TEST(ConfigIoTest, BadValuesNameTheKey) {
  struct Case {
    std::string content;
    std::string key;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {"seed: abc\n", "'seed'", "integer"},
      {"seed: 2.5\n", "'seed'", "integer"},
      {"scale: fast\n", "'scale'", "number"},
      {"name: 12\n", "'name'", "string"},
      {"tracking:\n  use_lines: maybe\n", "'tracking.use_lines'", "true or false"},
      {"tracking:\n  level_weights: 3\n", "'tracking.level_weights'", "list"},
      {"tracking:\n  level_weights: [1, a]\n", "'tracking.level_weights'", "element 1"},
      {"tracking: 5\n", "'tracking'", "section"},
      {"tracking:\n  solver:\n    kind: [1]\n", "'tracking.solver.kind'", "one of"},
      {"seed: 1\nseed: 2\n", "'seed'", "duplicate"},
      {"- 1\n- 2\n", "", "top level"},
  };
  for (const Case& c : cases) {
    const std::string message = LoadError(c.content);
    EXPECT_CONTAINS(message, "bad.yaml");
    EXPECT_CONTAINS(message, c.key);
    EXPECT_CONTAINS(message, c.reason);
  }
}

TEST(ConfigIoTest, BadEnumListsTheValidNames) {
  const std::string message = LoadError("tracking:\n  solver:\n    kind: dogleg\n");
  EXPECT_CONTAINS(message, "'tracking.solver.kind'");
  EXPECT_CONTAINS(message, "'dogleg'");
  EXPECT_CONTAINS(message, "ceres, gauss_newton, levenberg_marquardt");
}

TEST(ConfigIoTest, SyntaxErrorNamesTheFileAndLine) {
  const std::string message = LoadError("seed: 1\ntracking:\n  level_weights: [1, 2\n");
  EXPECT_CONTAINS(message, "bad.yaml:");
  EXPECT_CONTAINS(message, "syntax");
}

TEST(ConfigIoTest, Overrides) {
  TestOptions options;
  ApplyOverrides({"tracking.solver.kind=levenberg_marquardt", "tracking.use_lines=false",
                  "tracking.level_weights=1,2,3", "seed=-3", "scale = 0.25", "name=a=b"},
                 &options);
  EXPECT_EQ(options.tracking.solver.kind, SolverOptions::Kind::kLevenbergMarquardt);
  EXPECT_FALSE(options.tracking.use_lines);
  EXPECT_EQ(options.tracking.level_weights, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_EQ(options.seed, -3);
  EXPECT_EQ(options.scale, 0.25);
  EXPECT_EQ(options.name, "a=b");
  ApplyOverrides({"tracking.level_weights=[4, 5]"}, &options);
  EXPECT_EQ(options.tracking.level_weights, (std::vector<double>{4.0, 5.0}));
  ApplyOverrides({"tracking.level_weights="}, &options);
  EXPECT_TRUE(options.tracking.level_weights.empty());
  // Later overrides win.
  ApplyOverrides({"seed=1", "seed=2"}, &options);
  EXPECT_EQ(options.seed, 2);
}

TEST(ConfigIoTest, OverrideErrors) {
  std::string message = OverrideError({"tracking.solver.max_iter=3"});
  EXPECT_CONTAINS(message, "'tracking.solver.max_iter'");
  EXPECT_CONTAINS(message, "did you mean 'tracking.solver.max_iterations'");
  EXPECT_CONTAINS(message, "valid keys in 'tracking.solver': kind, max_iterations, tolerance");
  message = OverrideError({"tracking.bogus.key=1"});
  EXPECT_CONTAINS(message, "valid keys in 'tracking': solver.*, use_lines, level_weights");
  message = OverrideError({"sed=1"});
  EXPECT_CONTAINS(message, "did you mean 'seed'");
  EXPECT_CONTAINS(message, "at the top level");
  EXPECT_CONTAINS(OverrideError({"seed=1.5"}), "integer");
  EXPECT_CONTAINS(OverrideError({"seed=99999999999"}), "integer");
  EXPECT_CONTAINS(OverrideError({"scale=1.5x"}), "number");
  EXPECT_CONTAINS(OverrideError({"tracking.use_lines=yes please"}), "true or false");
  EXPECT_CONTAINS(OverrideError({"tracking.level_weights=1,,2"}), "comma-separated");
  message = OverrideError({"tracking.solver.kind=newton"});
  EXPECT_CONTAINS(message, "'newton'");
  EXPECT_CONTAINS(message, "ceres, gauss_newton, levenberg_marquardt");
  EXPECT_CONTAINS(OverrideError({"seed"}), "key=value");
  EXPECT_CONTAINS(OverrideError({"tracking=1"}), "section");
}

TEST(ConfigIoTest, WriteThenLoadGivesAnEqualStruct) {
  TestOptions options;
  options.name = "quote \" backslash \\ colon: hash # 00";
  options.scale = 1.0 / 3.0;
  options.seed = -2147483647;
  options.tracking.use_lines = false;
  options.tracking.level_weights = {0.1, -1e-300, 1e300, 20.0,
                                    std::numeric_limits<double>::infinity()};
  options.tracking.solver.kind = SolverOptions::Kind::kGaussNewton;
  options.tracking.solver.max_iterations = 0;
  options.tracking.solver.tolerance = 0.1 + 0.2;
  const std::string path = WriteFile("round_trip.yaml", "");
  WriteConfigYaml(options, path);
  TestOptions read;
  LoadConfigYaml(path, &read);
  EXPECT_TRUE(read == options) << ConfigToString(read) << "\nvs\n" << ConfigToString(options);

  for (const std::string& name : {std::string(""), std::string("00"), std::string("true")}) {
    TestOptions edge;
    edge.name = name;
    edge.tracking.level_weights.clear();
    WriteConfigYaml(edge, path);
    TestOptions edge_read;
    LoadConfigYaml(path, &edge_read);
    EXPECT_TRUE(edge_read == edge) << ConfigToString(edge);
  }
}

TEST(ConfigIoTest, WrittenConfigDocumentsEveryField) {
  const std::string text = ConfigToString(TestOptions());
  EXPECT_CONTAINS(text, "%YAML:1.0");
  EXPECT_CONTAINS(text, "# Frame-to-keyframe tracking.\ntracking:\n");
  EXPECT_CONTAINS(text,
                  "    # one of: ceres, gauss_newton, levenberg_marquardt\n    kind: ceres\n");
  EXPECT_CONTAINS(text, "  level_weights: [1.0, 0.5]\n");
  EXPECT_CONTAINS(text, "\nseed: 42\n");  // a top-level key after the sections
}

TEST(ConfigIoTest, DescribeIsAMarkdownTable) {
  const std::string table = DescribeConfig(TestOptions());
  EXPECT_CONTAINS(table, "| key | type | default | doc |\n| --- | --- | --- | --- |\n");
  EXPECT_CONTAINS(table,
                  "| **`tracking.solver`** | section | | The nonlinear least-squares solver. |");
  EXPECT_CONTAINS(table,
                  "| `tracking.solver.kind` | one of ceres, gauss_newton, levenberg_marquardt | "
                  "`ceres` | Which solver runs the tracking problem. |");
  EXPECT_CONTAINS(table, "| `seed` | int | `42` | Random seed. |");
  EXPECT_CONTAINS(table, "Weight per pyramid level \\| finest first.");  // escaped pipe
  // One row per field and section, plus the two header rows.
  int rows = 0;
  for (char c : table) rows += (c == '\n');
  EXPECT_EQ(rows, 2 + 8 + 2);
}

TEST(ConfigIoTest, CheckOptionsOrThrow) {
  TestOptions options;
  EXPECT_NO_THROW(CheckOptionsOrThrow(options, "config"));
  ApplyOverrides({"tracking.solver.max_iterations=0"}, &options);
  try {
    CheckOptionsOrThrow(options, "config x.yaml");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_CONTAINS(error.what(), "config x.yaml: tracking.solver.max_iterations must be > 0");
  }
}

}  // namespace
}  // namespace pldvo
