// The tracking reference's point budget (reference_builder.h) and the mapping worker's
// wait-instead-of-drop mode (mapping_worker.h).
#include "backend/reference_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <set>
#include <utility>

#include "backend/mapping_worker.h"
#include "backend/semi_dense_depth_map.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"

namespace pldvo {
namespace {

constexpr int kWidth = 96;
constexpr int kHeight = 64;

PinholeCamera Camera() {
  return PinholeCamera{kWidth, kHeight, 80.0, 80.0, kWidth / 2.0, kHeight / 2.0};
}

// A gradient image with texture everywhere (stereo finds matches on every row).
cv::Mat Texture() {
  cv::Mat image(kHeight, kWidth, CV_32F);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      image.at<float>(y, x) = static_cast<float>(128 + 60 * std::sin(0.7 * x) * std::cos(0.5 * y));
    }
  }
  return image;
}

// Every third pixel valid, inverse depth encoding its position.
SemiDenseDepthMap MapWithEveryThirdPixel(int* num_valid) {
  SemiDenseDepthMap map(kWidth, kHeight);
  *num_valid = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if ((x + y) % 3 != 0) continue;
      map.Set(map.Index(x, y), 0.2 + 1e-4 * map.Index(x, y), 0.01, 20);
      ++*num_valid;
    }
  }
  return map;
}

TEST(ReferenceBuilderTest, NoBudgetKeepsEveryValidHypothesis) {
  int num_valid = 0;
  const SemiDenseDepthMap map = MapWithEveryThirdPixel(&num_valid);
  const TrackingReference reference =
      BuildReferencePoints(map, ImagePyramid(Texture(), 3), Camera());
  EXPECT_EQ(static_cast<int>(reference.levels[0].points.size()), num_valid);
}

TEST(ReferenceBuilderTest, BudgetKeepsEvenlySpacedSubsetOfEveryLevel) {
  int num_valid = 0;
  const SemiDenseDepthMap map = MapWithEveryThirdPixel(&num_valid);
  const ImagePyramid keyframe(Texture(), 3);
  const TrackingReference full = BuildReferencePoints(map, keyframe, Camera());
  constexpr int kBudget = 300;
  const TrackingReference thinned = BuildReferencePoints(map, keyframe, Camera(), kBudget);
  for (int level = 0; level < 3; ++level) {
    const auto& all = full.levels[level].points;
    const auto& kept = thinned.levels[level].points;
    ASSERT_EQ(kept.size(), std::min<size_t>(all.size(), kBudget)) << "level " << level;
    // A subset, in raster order, whose consecutive members are at most ceil(n / budget) entries
    // of the full list apart: the thinned points cover the image like the full set.
    std::vector<int> positions;
    for (const ReferencePoint& point : kept) {
      const auto it = std::find_if(all.begin(), all.end(), [&](const ReferencePoint& p) {
        return p.pixel == point.pixel && p.idepth == point.idepth;
      });
      ASSERT_NE(it, all.end());
      positions.push_back(static_cast<int>(it - all.begin()));
    }
    const int max_gap = static_cast<int>((all.size() + kBudget - 1) / kBudget);
    EXPECT_EQ(positions.front(), 0);
    EXPECT_GE(positions.back(), static_cast<int>(all.size()) - max_gap);
    for (size_t k = 1; k < positions.size(); ++k) {
      EXPECT_GT(positions[k], positions[k - 1]);
      EXPECT_LE(positions[k] - positions[k - 1], max_gap);
    }
  }
}

TEST(MappingWorkerTest, WaitingWhenBehindRunsEveryUpdate) {
  // A burst of updates submitted faster than the thread maps them: with wait_when_behind the
  // submitter blocks instead, so no update is dropped and every job runs.
  MappingOptions options;
  MappingWorker worker(Camera(), options, /*parallel=*/true, /*max_pending_updates=*/1,
                       /*wait_when_behind=*/true);
  const cv::Mat image = Texture();
  MappingJob init;
  init.kind = MappingJob::Kind::kInitialize;
  init.keyframe_id = 0;
  init.frame_index = 0;
  init.image = image;
  init.num_levels = 3;
  worker.Submit(std::move(init));
  constexpr int kUpdates = 30;
  for (int i = 1; i <= kUpdates; ++i) {
    MappingJob update;
    update.kind = MappingJob::Kind::kUpdate;
    update.keyframe_id = 0;
    update.frame_index = i;
    update.image = image;
    update.cur_from_kf = SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.01 * i, 0.0, 0.0));
    EXPECT_GE(worker.Submit(std::move(update)), 0.0);
  }
  worker.Flush();
  EXPECT_EQ(worker.dropped_updates(), 0);
  EXPECT_EQ(worker.failed_jobs(), 0);
  EXPECT_EQ(static_cast<int>(worker.JobTimesMs().size()), kUpdates + 1);
  ASSERT_NE(worker.Latest(), nullptr);
  EXPECT_EQ(worker.Latest()->num_updates, kUpdates);
}

}  // namespace
}  // namespace pldvo
