#include "backend/odometry/keyframe_selector.h"

#include <gtest/gtest.h>

namespace pldvo {
namespace {

// A frame 2% of the mean scene depth from its keyframe, every point in view, all rows inliers:
// no criterion fires, and each test below moves one quantity past its threshold.
constexpr double kMeanIdepth = 0.5;
const SE3 kNear(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.04, 0.0, 0.0));

TEST(KeyframeSelectorTest, NoCriterionFiresOnANearFullyOverlappingWellTrackedFrame) {
  const KeyframeDecision d = DecideKeyframe(KeyframeOptions(), kNear, kMeanIdepth, 1.0, 0.9, 5);
  EXPECT_FALSE(d.new_keyframe) << d.reason;
  EXPECT_DOUBLE_EQ(d.relative_distance, 0.02);
}

TEST(KeyframeSelectorTest, EachCriterionFiresPastItsThreshold) {
  const KeyframeOptions options;  // 0.1, 0.7, 0.5
  const SE3 far(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.25, 0.0, 0.0));
  EXPECT_EQ(DecideKeyframe(options, far, kMeanIdepth, 1.0, 0.9, 5).reason, "distance");
  EXPECT_EQ(DecideKeyframe(options, kNear, kMeanIdepth, 0.6, 0.9, 5).reason, "overlap");
  // The keyframe no longer looks like the scene (exposure drift, blur): 40% inliers is tracked
  // (tracking.min_inlier_fraction 0.3) and starts a new keyframe.
  const KeyframeDecision faded = DecideKeyframe(options, kNear, kMeanIdepth, 1.0, 0.4, 5);
  EXPECT_TRUE(faded.new_keyframe);
  EXPECT_EQ(faded.reason, "inliers");
  KeyframeOptions off = options;
  off.min_inlier_fraction = 0.0;
  EXPECT_FALSE(DecideKeyframe(off, kNear, kMeanIdepth, 1.0, 0.4, 5).new_keyframe);
}

TEST(KeyframeSelectorTest, NoCriterionFiresBeforeMinFrames) {
  const KeyframeDecision d = DecideKeyframe(KeyframeOptions(), kNear, kMeanIdepth, 0.1, 0.1, 2);
  EXPECT_FALSE(d.new_keyframe);
}

TEST(KeyframeSelectorTest, InlierFractionOutsideTheUnitIntervalIsRejected) {
  KeyframeOptions options;
  options.min_inlier_fraction = 1.5;
  EXPECT_NE(options.Check(), "");
  options.min_inlier_fraction = -0.1;
  EXPECT_NE(options.Check(), "");
}

}  // namespace
}  // namespace pldvo
