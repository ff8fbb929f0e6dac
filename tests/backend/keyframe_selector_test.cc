#include "backend/odometry/keyframe_selector.h"

#include <gtest/gtest.h>

namespace pldvo {
namespace {

// A frame 2% of the mean scene depth from its keyframe, every point in view, all rows inliers:
// no criterion fires, and each test below moves one quantity past its threshold.
KeyframeEvidence Near() {
  KeyframeEvidence e;
  e.cur_from_kf = SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.04, 0.0, 0.0));
  e.mean_idepth = 0.5;
  e.overlap = 1.0;
  e.inlier_fraction = 0.9;
  e.rms_growth = 1.2;
  e.frames_tracked = 5;
  return e;
}

TEST(KeyframeSelectorTest, NoCriterionFiresOnANearFullyOverlappingWellTrackedFrame) {
  const KeyframeDecision d = DecideKeyframe(KeyframeOptions(), Near());
  EXPECT_FALSE(d.new_keyframe) << d.reason;
  EXPECT_DOUBLE_EQ(d.relative_distance, 0.02);
}

TEST(KeyframeSelectorTest, EachCriterionFiresPastItsThreshold) {
  KeyframeOptions options;  // 0.1, 0.7, 0.5; RMS growth off
  KeyframeEvidence far = Near();
  far.cur_from_kf = SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.25, 0.0, 0.0));
  EXPECT_EQ(DecideKeyframe(options, far).reason, "distance");
  KeyframeEvidence out_of_view = Near();
  out_of_view.overlap = 0.6;
  EXPECT_EQ(DecideKeyframe(options, out_of_view).reason, "overlap");
  // The keyframe no longer looks like the scene (exposure drift, blur): 40% inliers is tracked
  // (tracking.min_inlier_fraction 0.3) and starts a new keyframe.
  KeyframeEvidence faded = Near();
  faded.inlier_fraction = 0.4;
  EXPECT_TRUE(DecideKeyframe(options, faded).new_keyframe);
  EXPECT_EQ(DecideKeyframe(options, faded).reason, "inliers");
  KeyframeOptions off = options;
  off.min_inlier_fraction = 0.0;
  EXPECT_FALSE(DecideKeyframe(off, faded).new_keyframe);
  // The image is explained worse than right after the keyframe: RMS x1.6 against 1.5.
  KeyframeEvidence worse = Near();
  worse.rms_growth = 1.6;
  EXPECT_FALSE(DecideKeyframe(options, worse).new_keyframe);
  options.max_rms_growth = 1.5;
  EXPECT_EQ(DecideKeyframe(options, worse).reason, "rms");
  EXPECT_FALSE(DecideKeyframe(options, Near()).new_keyframe);
}

TEST(KeyframeSelectorTest, NoCriterionFiresBeforeMinFrames) {
  KeyframeEvidence e = Near();
  e.overlap = 0.1;
  e.inlier_fraction = 0.1;
  e.frames_tracked = 2;
  EXPECT_FALSE(DecideKeyframe(KeyframeOptions(), e).new_keyframe);
}

TEST(KeyframeSelectorTest, InlierFractionOutsideTheUnitIntervalIsRejected) {
  KeyframeOptions options;
  options.min_inlier_fraction = 1.5;
  EXPECT_NE(options.Check(), "");
  options.min_inlier_fraction = -0.1;
  EXPECT_NE(options.Check(), "");
}

TEST(KeyframeSelectorTest, RmsGrowthIsOffOrAboveOne) {
  KeyframeOptions options;
  EXPECT_EQ(options.Check(), "");
  options.max_rms_growth = 0.9;
  EXPECT_NE(options.Check(), "");
  options.max_rms_growth = 1.5;
  EXPECT_EQ(options.Check(), "");
}

}  // namespace
}  // namespace pldvo
