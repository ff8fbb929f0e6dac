// KeyframeWindow (backend/odometry/keyframe_window.h): observations are the centre pixels of traced
// segments; matches to the previous keyframe give the 3D line association; keyframes leave the
// window in order and their lines become anchored; a result moves the snapshot's keyframes to
// their refined poses and later keyframes rigidly with the newest refined one.
#include "backend/odometry/keyframe_window.h"

#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "frontend/line_segment.h"

namespace pldvo {
namespace {

PinholeCamera Camera() { return PinholeCamera{640, 480, 500.0, 500.0, 319.5, 239.5}; }

// Horizontal segments at rows `rows` (ids 0, 1, ...), traced from x = 10 to 49 with one pixel of
// widening above and below (as EdgeTracer with half_width_px = 1).
EdgeTrace HorizontalEdges(const std::vector<int>& rows) {
  EdgeTrace trace;
  for (size_t i = 0; i < rows.size(); ++i) {
    TracedLine line;
    line.id = static_cast<int>(i);
    line.segment =
        MakeLineSegment(Eigen::Vector2d(10.0, rows[i]), Eigen::Vector2d(49.0, rows[i]), 0, 1.0);
    for (int x = 49; x >= 10; --x) {  // reversed: the window orders pixels along the segment
      for (int dy = -1; dy <= 1; ++dy) line.pixels.emplace_back(x, rows[i] + dy);
    }
    trace.lines.push_back(line);
  }
  return trace;
}

// line_2d_id -> line_id of one window keyframe.
std::map<int, int> LineIds(const EdgeBAKeyframe& keyframe) {
  std::map<int, int> ids;
  for (const EdgeBAObservation& o : keyframe.observations) ids[o.line_2d_id] = o.line_id;
  return ids;
}

SE3 Pose(double x, double yaw) {
  return SE3(Eigen::Matrix3d(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())),
             Eigen::Vector3d(x, 0.1, 0.0));
}

TEST(KeyframeWindowTest, CentrePixelsAndAssociationFromMatches) {
  KeyframeWindow window(Camera(), 3, 8);
  window.AddKeyframe(0, SE3(), HorizontalEdges({100, 200}), {}, nullptr);
  const SE3 previous_from_kf = Pose(0.1, 0.0);
  // Segment 0 matched old segment 1, segment 2 matched old segment 0, segment 1 unmatched.
  window.AddKeyframe(1, previous_from_kf, HorizontalEdges({200, 300, 100}), {1, -1, 0},
                     &previous_from_kf);
  const EdgeBAWindow snapshot = window.MakeWindow();
  ASSERT_EQ(snapshot.keyframes.size(), 2u);
  const std::map<int, int> ids0 = LineIds(snapshot.keyframes[0]);
  const std::map<int, int> ids1 = LineIds(snapshot.keyframes[1]);
  ASSERT_EQ(ids0.size(), 2u);
  ASSERT_EQ(ids1.size(), 3u);
  EXPECT_EQ(ids1.at(0), ids0.at(1));
  EXPECT_EQ(ids1.at(2), ids0.at(0));
  EXPECT_NE(ids1.at(1), ids0.at(0));
  EXPECT_NE(ids1.at(1), ids0.at(1));
  EXPECT_FALSE(snapshot.keyframes[0].has_motion_prior);
  EXPECT_TRUE(snapshot.keyframes[1].has_motion_prior);
  EXPECT_TRUE(snapshot.keyframes[1].previous_from_this.translation().isApprox(
      previous_from_kf.translation()));
  // Only the centre row, 8 pixels evenly spaced from one end to the other, in order.
  const EdgeBAObservation& o = snapshot.keyframes[0].observations[0];
  ASSERT_EQ(o.pixels.size(), 8u);
  EXPECT_EQ(o.pixels.front(), Eigen::Vector2d(10.0, 100.0));
  EXPECT_EQ(o.pixels.back(), Eigen::Vector2d(49.0, 100.0));
  for (size_t i = 0; i < o.pixels.size(); ++i) {
    EXPECT_EQ(o.pixels[i].y(), 100.0);
    if (i > 0) {
      EXPECT_GT(o.pixels[i].x(), o.pixels[i - 1].x());
    }
  }
  EXPECT_TRUE(snapshot.lines.empty());  // nothing refined yet: the BA triangulates
}

TEST(KeyframeWindowTest, OldestLeavesAndItsRefinedLinesBecomeAnchored) {
  KeyframeWindow window(Camera(), 2, 0);
  window.AddKeyframe(0, SE3(), HorizontalEdges({100, 200}), {}, nullptr);
  window.AddKeyframe(1, Pose(0.1, 0.0), HorizontalEdges({100}), {0}, nullptr);
  EdgeBAWindow snapshot = window.MakeWindow();
  window.Remember(3, snapshot);
  const int shared = snapshot.keyframes[1].observations[0].line_id;
  EdgeBAResult result;
  result.sequence = 3;
  result.success = true;
  for (const EdgeBAKeyframe& k : snapshot.keyframes) {
    result.keyframes.push_back({k.id, k.cam_from_world, false});
  }
  EdgeBAResultLine refined;
  refined.line.id = shared;
  refined.line.point_in_world = Eigen::Vector3d(0.0, 0.0, 3.0);
  refined.status = EdgeBALineStatus::kOptimized;
  result.lines.push_back(refined);
  ASSERT_TRUE(window.Apply(result));
  EXPECT_FALSE(window.Apply(result));  // forgotten after use
  window.AddKeyframe(2, Pose(0.2, 0.0), HorizontalEdges({100}), {0}, nullptr);
  ASSERT_EQ(window.size(), 2);
  snapshot = window.MakeWindow();
  EXPECT_EQ(snapshot.keyframes.front().id, 1);
  ASSERT_EQ(snapshot.lines.size(), 1u);
  EXPECT_EQ(snapshot.lines[0].id, shared);
  EXPECT_TRUE(snapshot.lines[0].anchored);  // keyframe 0 observed it and left
  EXPECT_EQ(snapshot.lines[0].point_in_world, refined.line.point_in_world);
  SE3 pose;
  EXPECT_FALSE(window.WorldFromKeyframe(0, &pose));
  window.Clear();
  EXPECT_EQ(window.size(), 0);
}

TEST(KeyframeWindowTest, ResultMovesSnapshotAndLaterKeyframes) {
  KeyframeWindow window(Camera(), 5, 0);
  const SE3 world_from_0 = Pose(0.0, 0.0), world_from_1 = Pose(0.1, 0.05);
  const SE3 world_from_2 = Pose(0.2, 0.1);
  window.AddKeyframe(0, world_from_0, HorizontalEdges({100}), {}, nullptr);
  window.AddKeyframe(1, world_from_1, HorizontalEdges({100}), {0}, nullptr);
  const EdgeBAWindow snapshot = window.MakeWindow();
  window.Remember(0, snapshot);
  window.AddKeyframe(2, world_from_2, HorizontalEdges({100}), {0}, nullptr);  // after the snapshot

  EdgeBAResult failed;
  failed.sequence = 0;
  EXPECT_FALSE(window.Apply(failed));  // a failed solve changes nothing and is forgotten
  window.Remember(0, snapshot);
  EdgeBAResult unknown;
  unknown.sequence = 5;
  unknown.success = true;
  EXPECT_FALSE(window.Apply(unknown));

  const SE3 refined_world_from_1 = Pose(0.12, 0.06);
  EdgeBAResult result;
  result.sequence = 0;
  result.success = true;
  result.keyframes.push_back({0, world_from_0.Inverse(), true});
  result.keyframes.push_back({1, refined_world_from_1.Inverse(), false});
  ASSERT_TRUE(window.Apply(result));
  SE3 pose;
  ASSERT_TRUE(window.WorldFromKeyframe(0, &pose));
  EXPECT_LT((pose.Inverse() * world_from_0).Log().norm(), 1e-12);
  ASSERT_TRUE(window.WorldFromKeyframe(1, &pose));
  EXPECT_LT((pose.Inverse() * refined_world_from_1).Log().norm(), 1e-12);
  // Keyframe 2 keeps its pose relative to keyframe 1.
  ASSERT_TRUE(window.WorldFromKeyframe(2, &pose));
  const SE3 expected = refined_world_from_1 * world_from_1.Inverse() * world_from_2;
  EXPECT_LT((pose.Inverse() * expected).Log().norm(), 1e-12);
  EXPECT_GT((pose.Inverse() * world_from_2).Log().norm(), 1e-3);
}

}  // namespace
}  // namespace pldvo
