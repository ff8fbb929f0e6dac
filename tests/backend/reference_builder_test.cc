// The tracking reference's point budget and edge foot points (reference_builder.h) and the
// mapping worker's wait-instead-of-drop mode and inline lag (mapping_worker.h).
#include "backend/odometry/reference_builder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <set>
#include <utility>

#include "backend/mapping/depth_mapper.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "backend/odometry/mapping_worker.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/statistics.h"
#include "frontend/line_frontend.h"
#include "residuals/covariance_models.h"
#include "tests/backend/rendered_sequence.h"

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

// A traced edge is a band of pixels up to 1.5 px off its keyframe line; the point-to-line
// residual must reproject the foot points on the line, at every level.
TEST(ReferenceBuilderTest, EdgePointsCarryTheirFootPointOnTheKeyframeLine) {
  // l: 0.6 x - 0.8 y + 7 = 0 (unit normal), traced as the pixels within 1.5 px of it.
  const Eigen::Vector3d line(0.6, -0.8, 7.0);
  SemiDenseDepthMap map(kWidth, kHeight);
  int off_line = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double distance = line.dot(Eigen::Vector3d(x, y, 1.0));
      if (std::abs(distance) > 1.5) continue;
      off_line += std::abs(distance) > 0.5;
      map.SetCandidate(map.Index(x, y), true, 0);
      map.Set(map.Index(x, y), 0.5, 0.01, 20);
    }
  }
  ASSERT_GT(off_line, 50);
  const ImagePyramid keyframe(Texture(), 3);
  const TrackingReference reference = BuildReferencePoints(map, keyframe, Camera(), 0, {line});
  const TrackingReference without_lines = BuildReferencePoints(map, keyframe, Camera());
  for (int level = 0; level < 3; ++level) {
    LineWithCovariance level0;
    level0.line = line;
    const Eigen::Vector3d l = LineAtLevel(level0, level).line;
    const auto& points = reference.levels[level].points;
    ASSERT_FALSE(points.empty());
    for (size_t i = 0; i < points.size(); ++i) {
      const ReferencePoint& point = points[i];
      ASSERT_EQ(point.edge_id, 0);
      EXPECT_NEAR(l.dot(point.pixel_on_edge.homogeneous()), 0.0, 1e-12) << "level " << level;
      // The foot point: the pixel moved along the normal by its distance to the line.
      const Eigen::Vector2d step = point.pixel - point.pixel_on_edge;
      EXPECT_NEAR(step.norm(), std::abs(l.dot(point.pixel.homogeneous())), 1e-12);
      if (step.norm() > 1e-6) {
        EXPECT_NEAR(std::abs(step.normalized().dot(l.head<2>())), 1.0, 1e-9);
      }
      EXPECT_EQ(without_lines.levels[level].points[i].pixel_on_edge, point.pixel);
    }
  }
}

// On a rendered sequence with GT keyframe depth, the real frontend's traced edges and matches:
// at the true pose, the reprojected foot points lie on the matched lines (up to the detector's
// and the depth map's error), while the traced pixels themselves lie up to 1.5 px off them.
TEST(ReferenceBuilderTest, FootPointsReprojectOntoTheMatchedLinesAtTheTruePose) {
  constexpr int kFrame = 5;
  const test::RenderedSequence rendered = test::RenderLowtexSequence(kFrame + 1);
  const PinholeCamera& camera = rendered.sequence.camera;
  LineFrontend frontend{LineFrontendOptions()};
  LineFrame keyframe = frontend.Process(rendered.images[0]);
  LineFrame frame = frontend.Process(rendered.images[kFrame]);
  const std::vector<LineMatch> matches = frontend.Match(&keyframe, &frame);
  const EdgeTrace edges = frontend.TraceMatched(keyframe, matches);
  DepthMapper mapper(camera, MappingOptions());
  mapper.InitializeKeyframeFromDepth(rendered.images[0], edges, rendered.first_depth, 1e-4);
  TrackingReference reference = BuildReferencePoints(
      mapper.depth_map(), ImagePyramid(rendered.images[0], 1), camera, 0, mapper.keyframe_lines());
  SetMatchedLines(
      MatchedLinesFromMatches(matches, frame.segments, static_cast<int>(keyframe.segments.size())),
      &reference);
  const SE3 cur_from_ref = rendered.sequence.ground_truth[kFrame].world_from_cam.Inverse() *
                           rendered.sequence.ground_truth[0].world_from_cam;
  std::vector<double> foot, traced;
  for (const ReferencePoint& point : reference.levels[0].points) {
    if (point.edge_id < 0 || !reference.levels[0].lines_in_cur[point.edge_id].matched) continue;
    const Eigen::Vector3d& l = reference.levels[0].lines_in_cur[point.edge_id].line_in_cur.line;
    Eigen::Vector2d on_edge, at_pixel;
    if (!Reproject(camera, cur_from_ref, point.pixel_on_edge, point.idepth, &on_edge) ||
        !Reproject(camera, cur_from_ref, point.pixel, point.idepth, &at_pixel)) {
      continue;
    }
    foot.push_back(std::abs(l.dot(on_edge.homogeneous())));
    traced.push_back(std::abs(l.dot(at_pixel.homogeneous())));
  }
  ASSERT_GT(foot.size(), 500u);
  std::printf("edge pixels %zu: median |l^T x'| foot points %.3f px, traced pixels %.3f px\n",
              foot.size(), Median(foot), Median(traced));
  EXPECT_LT(Median(foot), 0.25);
  EXPECT_GT(Median(traced), 0.4);
}

// Mapping jobs on one textured image: a keyframe (new, or a switch new_from_old) and a frame
// update at 1 cm per frame index along x.
MappingJob KeyframeJob(MappingJob::Kind kind, int keyframe_id, int frame_index,
                       const cv::Mat& image) {
  MappingJob job;
  job.kind = kind;
  job.keyframe_id = keyframe_id;
  job.frame_index = frame_index;
  job.image = image;
  job.num_levels = 3;
  return job;
}

MappingJob UpdateJob(int keyframe_id, int frame_index, const cv::Mat& image) {
  MappingJob update;
  update.kind = MappingJob::Kind::kUpdate;
  update.keyframe_id = keyframe_id;
  update.frame_index = frame_index;
  update.image = image;
  update.cur_from_kf =
      SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.01 * frame_index, 0.0, 0.0));
  return update;
}

TEST(MappingWorkerTest, WaitingWhenBehindRunsEveryUpdate) {
  // A burst of updates submitted faster than the thread maps them: with wait_when_behind none is
  // dropped and every job runs.
  MappingOptions options;
  MappingWorker worker(Camera(), options, /*parallel=*/true, /*max_pending_updates=*/1,
                       /*wait_when_behind=*/true);
  const cv::Mat image = Texture();
  worker.Submit(KeyframeJob(MappingJob::Kind::kInitialize, 0, 0, image));
  constexpr int kUpdates = 30;
  for (int i = 1; i <= kUpdates; ++i) worker.Submit(UpdateJob(0, i, image));
  worker.Flush();
  EXPECT_EQ(worker.dropped_updates(), 0);
  EXPECT_EQ(worker.failed_jobs(), 0);
  EXPECT_EQ(static_cast<int>(worker.JobTimesMs().size()), kUpdates + 1);
  ASSERT_NE(worker.Latest(), nullptr);
  EXPECT_EQ(worker.Latest()->num_updates, kUpdates);
}

TEST(MappingWorkerTest, InlineLagHoldsUpdatesBackUntilTheNextKeyframe) {
  // Inline with a lag of 2: the published map holds every update but the newest two; a keyframe
  // switch first runs the held-back ones, so the retired keyframe saw every frame.
  constexpr int kLag = 2;
  MappingOptions options;
  MappingWorker worker(Camera(), options, /*parallel=*/false, /*max_pending_updates=*/2,
                       /*wait_when_behind=*/true, kLag);
  const cv::Mat image = Texture();
  worker.Submit(KeyframeJob(MappingJob::Kind::kInitialize, 0, 0, image));
  constexpr int kUpdates = 5;
  for (int i = 1; i <= kUpdates; ++i) {
    worker.Submit(UpdateJob(0, i, image));
    ASSERT_NE(worker.Latest(), nullptr);
    EXPECT_EQ(worker.Latest()->num_updates, std::max(0, i - kLag)) << "after update " << i;
  }
  MappingJob next = KeyframeJob(MappingJob::Kind::kNewKeyframe, 1, kUpdates + 1, image);
  next.new_from_old = SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.06, 0.0, 0.0));
  next.keep_retired_map = true;
  worker.Submit(std::move(next));
  // Every job ran: the held-back updates before the switch (after it they would be skipped as
  // updates of a retired keyframe, and not timed).
  EXPECT_EQ(static_cast<int>(worker.JobTimesMs().size()), kUpdates + 2);
  EXPECT_EQ(worker.failed_jobs(), 0);
  ASSERT_NE(worker.Latest(), nullptr);
  EXPECT_EQ(worker.Latest()->keyframe_id, 1);
  EXPECT_EQ(worker.Latest()->num_updates, 0);
  worker.Submit(UpdateJob(1, kUpdates + 2, image));
  EXPECT_EQ(worker.Latest()->num_updates, 0);
  worker.Flush();
  EXPECT_EQ(worker.Latest()->num_updates, 1);
}

TEST(MappingWorkerTest, TrackingGetsTheLaggedMapOnEitherThread) {
  // MapForTracking with a lag of 2: every update but the newest two, inline and on the thread,
  // even when the thread has already run them all; after a keyframe switch, the new keyframe's
  // map.
  constexpr int kLag = 2;
  const cv::Mat image = Texture();
  for (const bool parallel : {false, true}) {
    SCOPED_TRACE(parallel ? "parallel" : "inline");
    MappingOptions options;
    MappingWorker worker(Camera(), options, parallel, /*max_pending_updates=*/1,
                         /*wait_when_behind=*/true, kLag);
    worker.Submit(KeyframeJob(MappingJob::Kind::kInitialize, 0, 0, image));
    ASSERT_NE(worker.MapForTracking(0), nullptr);
    EXPECT_EQ(worker.MapForTracking(0)->num_updates, 0);
    constexpr int kUpdates = 5;
    for (int i = 1; i <= kUpdates; ++i) {
      worker.Submit(UpdateJob(0, i, image));
      if (parallel) worker.Flush();  // inline, Flush runs the held-back updates
      EXPECT_EQ(worker.MapForTracking(0)->num_updates, std::max(0, i - kLag)) << "update " << i;
    }
    if (parallel) {
      EXPECT_EQ(worker.Latest()->num_updates, kUpdates);
    }
    MappingJob next = KeyframeJob(MappingJob::Kind::kNewKeyframe, 1, kUpdates + 1, image);
    next.new_from_old = SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.06, 0.0, 0.0));
    worker.Submit(std::move(next));
    const std::shared_ptr<const KeyframeMap> switched = worker.MapForTracking(1);
    EXPECT_EQ(switched->keyframe_id, 1);
    EXPECT_EQ(switched->num_updates, 0);
    worker.Submit(UpdateJob(1, kUpdates + 2, image));
    worker.Submit(UpdateJob(1, kUpdates + 3, image));
    EXPECT_EQ(worker.MapForTracking(1)->num_updates, 0);
    worker.Submit(UpdateJob(1, kUpdates + 4, image));
    EXPECT_EQ(worker.MapForTracking(1)->num_updates, 1);
    EXPECT_EQ(worker.dropped_updates(), 0);
    EXPECT_EQ(worker.failed_jobs(), 0);
  }
}

TEST(MappingWorkerTest, KeyframeSwitchPropagatesThePublishedMap) {
  // The switch propagates (and keeps as the retired map) the map the last update published
  // instead of regularising the same state again: the retired map is that very map, and the new
  // keyframe's map is the one of a DepthMapper fed the same frames directly.
  MappingOptions options;
  ASSERT_TRUE(options.regularize);
  MappingWorker worker(Camera(), options, /*parallel=*/false, /*max_pending_updates=*/2);
  const cv::Mat image = Texture();
  DepthMapper direct(Camera(), options);
  worker.Submit(KeyframeJob(MappingJob::Kind::kInitialize, 0, 0, image));
  direct.InitializeKeyframe(image, EdgeTrace());
  for (int i = 1; i <= 3; ++i) {
    const MappingJob update = UpdateJob(0, i, image);
    worker.Submit(update);
    direct.UpdateWithFrame(image, update.cur_from_kf, {});
  }
  const std::shared_ptr<const KeyframeMap> before = worker.Latest();
  MappingJob next = KeyframeJob(MappingJob::Kind::kNewKeyframe, 1, 4, image);
  next.new_from_old = SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.03, 0.0, 0.0));
  next.keep_retired_map = true;
  worker.Submit(next);
  direct.PropagateToNewKeyframe(image, EdgeTrace(), next.new_from_old);
  const std::shared_ptr<const KeyframeMap> after = worker.Latest();
  ASSERT_EQ(after->keyframe_id, 1);
  EXPECT_EQ(after->retired_map, before->map);
  EXPECT_FALSE(after->random_init);
  const SemiDenseDepthMap expected =
      direct.RegularizedMap(options.regularize, options.line_regularization);
  const SemiDenseDepthMap& got = *after->map;
  int valid = 0, differ = 0;
  for (int i = 0; i < expected.num_pixels(); ++i) {
    valid += expected.valid(i);
    differ += expected.valid(i) != got.valid(i) ||
              (expected.valid(i) && (expected.idepth(i) != got.idepth(i) ||
                                     expected.idepth_var(i) != got.idepth_var(i)));
  }
  EXPECT_GT(valid, 100);
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(worker.failed_jobs(), 0);
}

TEST(MappingWorkerTest, CountsTheUpdatesSinceTheLastRandomInitialisation) {
  // KeyframeMap::updates_since_random_init (odometry.random_map_warmup_updates): 0 on a random
  // map, +1 per fused update, carried across a switch that propagates the map, 0 again when the
  // switch re-initialises at random, -1 on a map from a depth image.
  MappingOptions options;
  MappingWorker worker(Camera(), options, /*parallel=*/false, /*max_pending_updates=*/2);
  const cv::Mat image = Texture();
  worker.Submit(KeyframeJob(MappingJob::Kind::kInitialize, 0, 0, image));
  EXPECT_EQ(worker.Latest()->updates_since_random_init, 0);
  EXPECT_TRUE(worker.Latest()->random_init);
  for (int i = 1; i <= 2; ++i) {
    worker.Submit(UpdateJob(0, i, image));
    EXPECT_EQ(worker.Latest()->updates_since_random_init, i);
  }
  MappingJob propagate = KeyframeJob(MappingJob::Kind::kNewKeyframe, 1, 3, image);
  propagate.new_from_old = SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.02, 0.0, 0.0));
  worker.Submit(std::move(propagate));
  ASSERT_EQ(worker.Latest()->keyframe_id, 1);
  EXPECT_FALSE(worker.Latest()->random_init);
  EXPECT_EQ(worker.Latest()->updates_since_random_init, 2);
  worker.Submit(UpdateJob(1, 4, image));
  EXPECT_EQ(worker.Latest()->updates_since_random_init, 3);
  MappingJob reinit = KeyframeJob(MappingJob::Kind::kNewKeyframe, 2, 5, image);
  reinit.min_propagated_points = image.rows * image.cols + 1;  // never kept: random map
  worker.Submit(std::move(reinit));
  ASSERT_EQ(worker.Latest()->keyframe_id, 2);
  EXPECT_TRUE(worker.Latest()->random_init);
  EXPECT_EQ(worker.Latest()->updates_since_random_init, 0);
  MappingJob from_depth = KeyframeJob(MappingJob::Kind::kInitialize, 3, 6, image);
  from_depth.depth = cv::Mat(image.size(), CV_32F, cv::Scalar(1.0f));
  from_depth.depth_idepth_var = 1e-4;
  worker.Submit(std::move(from_depth));
  worker.Submit(UpdateJob(3, 7, image));
  ASSERT_EQ(worker.Latest()->keyframe_id, 3);
  EXPECT_EQ(worker.Latest()->updates_since_random_init, -1);
  EXPECT_EQ(worker.failed_jobs(), 0);
}

}  // namespace
}  // namespace pldvo
