#include "backend/odometry/solver_comparison.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "backend/tracking/tracker.h"
#include "core/se3.h"

namespace pldvo {
namespace {

// A tracked frame whose compared pose is `offset_m` along x from the run's, with both solvers'
// final costs.
OdometryFrameResult ComparedFrame(int index, double offset_m, double run_cost,
                                  double compared_cost) {
  OdometryFrameResult frame;
  frame.index = index;
  frame.timestamp = 0.1 * index;
  frame.status = FrameStatus::kTracked;
  frame.world_from_cam = SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(index, 0, 0));
  frame.tracking.levels.emplace_back();
  frame.tracking.levels.back().final_cost = run_cost;
  frame.tracking.valid_residuals = 100 + index;
  frame.compared = true;
  frame.compared_status = TrackingStatus::kConverged;
  frame.world_from_cam_compared =
      frame.world_from_cam * SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(offset_m, 0, 0));
  frame.compared_final_cost = compared_cost;
  frame.compared_valid_residuals = 90 + index;
  return frame;
}

// The summary names the frames where the two solvers differ most, largest first, with both final
// costs: what tells a convergence failure from two minima.
TEST(SolverComparisonTest, ListsTheLargestDifferencesWithBothCosts) {
  const std::string path = testing::TempDir() + "/solver_comparison_test.txt";
  SolverComparison comparison(path, "ceres");
  ASSERT_TRUE(comparison.ok());
  const double offsets[] = {1e-6, 3e-2, 2e-6, 5e-3, 1e-6, 4e-5, 7e-2, 3e-6};
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(comparison.Add(ComparedFrame(i + 1, offsets[i], 10.0 + i, 20.0 + i)));
  }
  const nlohmann::json summary = comparison.Summary(nullptr);
  EXPECT_EQ(summary["frames_compared"].get<int>(), 8);
  EXPECT_NEAR(summary["translation_diff_m_max"].get<double>(), 7e-2, 1e-12);
  const nlohmann::json& largest = summary["largest_differences"];
  ASSERT_EQ(largest.size(), static_cast<size_t>(SolverComparison::kLargestDifferences));
  const int expected_frames[] = {7, 2, 4, 6, 8};
  for (int i = 0; i < SolverComparison::kLargestDifferences; ++i) {
    const int frame = expected_frames[i];
    EXPECT_EQ(largest[i]["frame"].get<int>(), frame);
    EXPECT_NEAR(largest[i]["translation_m"].get<double>(), offsets[frame - 1], 1e-12);
    EXPECT_EQ(largest[i]["run_cost"].get<double>(), 10.0 + frame - 1);
    EXPECT_EQ(largest[i]["compared_cost"].get<double>(), 20.0 + frame - 1);
    EXPECT_EQ(largest[i]["run_valid_rows"].get<int>(), 100 + frame);
    EXPECT_EQ(largest[i]["compared_valid_rows"].get<int>(), 90 + frame);
  }
  EXPECT_NE(comparison.Line(summary).find("largest at frame 7"), std::string::npos)
      << comparison.Line(summary);
  std::remove(path.c_str());
}

TEST(SolverComparisonTest, FewerFramesThanTheListLength) {
  const std::string path = testing::TempDir() + "/solver_comparison_short_test.txt";
  SolverComparison comparison(path, "gauss_newton");
  ASSERT_TRUE(comparison.ok());
  const nlohmann::json empty = comparison.Summary(nullptr);
  EXPECT_TRUE(empty["largest_differences"].empty());
  EXPECT_EQ(comparison.Line(empty).find("largest"), std::string::npos);
  ASSERT_TRUE(comparison.Add(ComparedFrame(1, 2e-3, 1.0, 2.0)));
  ASSERT_TRUE(comparison.Add(ComparedFrame(2, 1e-3, 1.0, 2.0)));
  const nlohmann::json summary = comparison.Summary(nullptr);
  ASSERT_EQ(summary["largest_differences"].size(), 2u);
  EXPECT_EQ(summary["largest_differences"][0]["frame"].get<int>(), 1);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace pldvo
