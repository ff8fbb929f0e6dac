// `pldvo compare` through the binary: two ablations' results.csv (written here in ablate's
// layout), the table and summary it prints, its JSON, and its errors.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/experiments/test_folder.h"

namespace pldvo {
namespace {

namespace fs = std::filesystem;
using test::Pldvo;
using test::Slurp;
using test::TestRoot;

// An ablation folder with results.csv in `pldvo ablate`'s column order (a subset of the columns
// after `dir` is enough: compare reads them by name).
fs::path Ablation(const std::string& name, const std::string& rows) {
  const fs::path dir = TestRoot() / name;
  fs::create_directories(dir);
  std::ofstream(dir / "results.csv")
      << "dataset,config,status,frames,tracked,keyframes,lost_events,rpe_cm_s,rpe_deg_s,ate_m\n"
      << rows;
  return dir;
}

TEST(CompareCommandTest, PrintsRatiosAndTheirGeometricMean) {
  // Both configs in one ablation: lowtex 2.0 -> 1.0, boxes 4.0 -> 8.0 (one failed run).
  const fs::path both = Ablation("both",
                                 "lowtex,sdvo,ok,10,10,2,0,2.0,0.1,0.01\n"
                                 "lowtex,points_lines,ok,10,10,2,0,1.0,0.1,0.01\n"
                                 "boxes,sdvo,ok,10,10,2,0,4.0,0.1,0.01\n"
                                 "boxes,points_lines,ok,10,10,2,0,8.0,0.1,0.01\n"
                                 "boxes,points_lines,failed_exit_1,,,,,,,\n");
  const fs::path log = TestRoot() / "compare.log";
  ASSERT_EQ(Pldvo("compare --baseline " + both.string() + " --baseline_config sdvo --candidate " +
                      both.string() + " --candidate_config points_lines",
                  log),
            0)
      << Slurp(log);
  const std::string text = Slurp(log);
  EXPECT_NE(text.find("| lowtex | 2.0000 | 1 | 1.0000 | 1 | 0.500 |"), std::string::npos) << text;
  EXPECT_NE(text.find("| boxes | 4.0000 | 1 | 8.0000 | 1 (+1 failed) | 2.000 |"), std::string::npos)
      << text;
  EXPECT_NE(text.find("geometric mean of the ratios 1.000"), std::string::npos) << text;
  EXPECT_NE(text.find("better by more than 10%: 1 of 2, worse: 1"), std::string::npos) << text;

  const fs::path json_log = TestRoot() / "compare_json.log";
  ASSERT_EQ(Pldvo("compare --json --metric rpe_deg_s --baseline " + both.string() +
                      "/results.csv --baseline_config sdvo --candidate " + both.string() +
                      " --candidate_config points_lines",
                  json_log),
            0)
      << Slurp(json_log);
  const nlohmann::json json = nlohmann::json::parse(Slurp(json_log));
  EXPECT_EQ(json["metric"], "rpe_deg_s");
  EXPECT_EQ(json["rows"].size(), 2u);
  EXPECT_DOUBLE_EQ(json["geometric_mean_ratio"].get<double>(), 1.0);
  EXPECT_EQ(json["candidate_failed"], 1);
}

TEST(CompareCommandTest, TwoAblationsOfOneConfigEachNeedNoConfigName) {
  const fs::path base = Ablation("base", "a,points_lines,ok,1,1,1,0,1.0,1,1\n");
  const fs::path cand = Ablation("cand", "a,points_lines,ok,1,1,1,0,0.5,1,1\n");
  const fs::path log = TestRoot() / "one.log";
  ASSERT_EQ(Pldvo("compare --baseline " + base.string() + " --candidate " + cand.string(), log), 0)
      << Slurp(log);
  EXPECT_NE(Slurp(log).find("geometric mean of the ratios 0.500"), std::string::npos) << Slurp(log);
}

TEST(CompareCommandTest, FilterKeepsTheMatchingSequences) {
  const fs::path base = Ablation("filter_base",
                                 "lowtex_s1,points_lines,ok,1,1,1,0,1.0,1,1\n"
                                 "lowtex_s3,points_lines,ok,1,1,1,0,1.0,1,1\n");
  const fs::path cand = Ablation("filter_cand",
                                 "lowtex_s1,points_lines,ok,1,1,1,0,4.0,1,1\n"
                                 "lowtex_s3,points_lines,ok,1,1,1,0,0.5,1,1\n");
  const fs::path log = TestRoot() / "filter.log";
  ASSERT_EQ(Pldvo("compare --filter '_s[345]$' --baseline " + base.string() + " --candidate " +
                      cand.string(),
                  log),
            0)
      << Slurp(log);
  EXPECT_NE(Slurp(log).find("sequences compared: 1\n"), std::string::npos) << Slurp(log);
  EXPECT_NE(Slurp(log).find("geometric mean of the ratios 0.500"), std::string::npos) << Slurp(log);
  EXPECT_EQ(Slurp(log).find("lowtex_s1"), std::string::npos) << Slurp(log);
  EXPECT_EQ(
      Pldvo("compare --filter '(' --baseline " + base.string() + " --candidate " + cand.string(),
            log),
      2);
  EXPECT_NE(Slurp(log).find("is not a regular expression"), std::string::npos) << Slurp(log);
}

TEST(CompareCommandTest, UsageErrorsExitTwoAndUnreadableFilesOne) {
  const fs::path both = Ablation("errors",
                                 "a,sdvo,ok,1,1,1,0,1.0,1,1\n"
                                 "a,points_lines,ok,1,1,1,0,0.5,1,1\n");
  const fs::path log = TestRoot() / "errors.log";
  EXPECT_EQ(Pldvo("compare --baseline " + both.string(), log), 2);
  EXPECT_NE(Slurp(log).find("--baseline and --candidate are required"), std::string::npos);
  // Two configs in the file and none chosen.
  EXPECT_EQ(Pldvo("compare --baseline " + both.string() + " --candidate " + both.string(), log), 2);
  EXPECT_NE(Slurp(log).find("holds 2 configs"), std::string::npos) << Slurp(log);
  EXPECT_EQ(Pldvo("compare --baseline " + both.string() + " --baseline_config nope --candidate " +
                      both.string() + " --candidate_config sdvo",
                  log),
            2);
  EXPECT_NE(Slurp(log).find("has no config 'nope'"), std::string::npos) << Slurp(log);
  EXPECT_EQ(
      Pldvo("compare --metric nope --baseline " + both.string() +
                " --baseline_config sdvo --candidate " + both.string() + " --candidate_config sdvo",
            log),
      2);
  EXPECT_NE(Slurp(log).find("no column 'nope'"), std::string::npos) << Slurp(log);
  EXPECT_EQ(Pldvo("compare --baseline " + (TestRoot() / "missing").string() + " --candidate " +
                      both.string() + " --candidate_config sdvo",
                  log),
            1);
  EXPECT_NE(Slurp(log).find("cannot read"), std::string::npos) << Slurp(log);
}

}  // namespace
}  // namespace pldvo
