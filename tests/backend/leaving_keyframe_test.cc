// ChooseLeavingKeyframe (backend/windowed_ba/leaving_keyframe.h): which keyframe leaves a full
// window. Keyframes on a line with known distances, so the distance score's choice follows by
// hand; a keyframe out of view of the newest leaves first; the choice does not depend on the
// map's scale or the world's origin; WindowedBAKeyframes keeps what the choice keeps.
#include "backend/windowed_ba/leaving_keyframe.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "backend/odometry/windowed_ba_keyframes.h"

namespace pldvo {
namespace {

std::vector<LeavingCandidate> OnALine(const std::vector<double>& x) {
  std::vector<LeavingCandidate> keyframes(x.size());
  for (size_t k = 0; k < x.size(); ++k) keyframes[k].centre = Eigen::Vector3d(x[k], 0.0, 0.0);
  return keyframes;
}

// Centres 0, 5, 5.5, 6 | 6.5, 7 (the newest two protected). Scores sqrt(d(i, 7)) * sum_j
// 1 / d(i, j): 0 -> 2.24, 5 -> 6.18, 5.5 -> 7.16, 6 -> 6.17. The one inside the cluster leaves,
// the distant first keyframe (the long baseline) stays; oldest would drop it.
TEST(LeavingKeyframeTest, AClusteredKeyframeLeavesAndTheDistantOneStays) {
  const std::vector<LeavingCandidate> keyframes = OnALine({0.0, 5.0, 5.5, 6.0, 6.5, 7.0});
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.05), 2);
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kOldest, 2, 0.05), 0);
}

TEST(LeavingKeyframeTest, DoesNotDependOnScaleOrOrigin) {
  std::vector<LeavingCandidate> keyframes = OnALine({0.0, 5.0, 5.5, 6.0, 6.5, 7.0});
  const Eigen::Vector3d origin(-3.0, 40.0, 2.0);
  for (LeavingCandidate& k : keyframes) k.centre = 1e-3 * k.centre + origin;
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.05), 2);
  for (LeavingCandidate& k : keyframes) k.centre = 1e6 * (k.centre - origin);
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.05), 2);
}

TEST(LeavingKeyframeTest, CoincidentKeyframesLeaveFirst) {
  // Pure rotation: keyframes 1 and 2 at one centre; one of them leaves, not the others.
  const int leaving = ChooseLeavingKeyframe(OnALine({0.0, 1.0, 1.0, 3.0, 4.0, 5.0}),
                                            LeavingKeyframe::kSpread, 2, 0.05);
  EXPECT_TRUE(leaving == 1 || leaving == 2) << leaving;
  // Every centre the same: nothing to tell them apart, the oldest leaves.
  EXPECT_EQ(ChooseLeavingKeyframe(OnALine({2.0, 2.0, 2.0, 2.0}), LeavingKeyframe::kSpread, 2, 0.05),
            0);
}

TEST(LeavingKeyframeTest, AKeyframeOutOfViewOfTheNewestLeavesFirst) {
  std::vector<LeavingCandidate> keyframes = OnALine({0.0, 5.0, 5.5, 6.0, 6.5, 7.0});
  keyframes[3].visible_in_newest = 0.04;
  keyframes[1].visible_in_newest = 0.5;
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.05), 3);
  // The oldest of those out of view; below the threshold only.
  keyframes[0].visible_in_newest = 0.0;
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.05), 0);
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.0), 2);
  // A protected keyframe never leaves, in view or not.
  keyframes = OnALine({0.0, 5.0, 5.5, 6.0, 6.5, 7.0});
  keyframes[4].visible_in_newest = 0.0;
  EXPECT_EQ(ChooseLeavingKeyframe(keyframes, LeavingKeyframe::kSpread, 2, 0.05), 2);
}

TEST(LeavingKeyframeTest, RejectsAWindowWithNothingToLeave) {
  EXPECT_THROW(ChooseLeavingKeyframe(OnALine({0.0, 1.0}), LeavingKeyframe::kSpread, 2, 0.05),
               std::invalid_argument);
  EXPECT_THROW(ChooseLeavingKeyframe(OnALine({0.0, 1.0}), LeavingKeyframe::kOldest, 0, 0.05),
               std::invalid_argument);
}

// The odometry's record: a window of 5 keyframes at the centres above, added one by one. With
// spread the sixth keyframe makes 5.5 leave (the records keep ids 0, 1, 3, 4, 5); with oldest
// keyframe 0 leaves. Departed() says which left.
TEST(LeavingKeyframeTest, WindowedBAKeyframesKeepWhatTheChoiceKeeps) {
  const PinholeCamera camera{32, 24, 30.0, 30.0, 15.5, 11.5};  // width, height, fx, fy, cx, cy
  const cv::Mat image(camera.height, camera.width, CV_32F, cv::Scalar(100.0f));
  const std::vector<double> x = {0.0, 5.0, 5.5, 6.0, 6.5, 7.0};
  for (const LeavingKeyframe policy : {LeavingKeyframe::kSpread, LeavingKeyframe::kOldest}) {
    WindowedBAKeyframes window(camera, 5, policy, 0.05);
    for (int k = 0; k < 6; ++k) {
      window.AddKeyframe(k, 10 * k, 0.1 * k, SE3(Eigen::Matrix3d::Identity(), {x[k], 0.0, 0.0}),
                         image, {}, {}, AffineBrightness());
    }
    std::vector<int> recorded;
    for (const KeyframePoseRecord& record : window.Recorded()) recorded.push_back(record.id);
    ASSERT_EQ(window.Departed().size(), 1u);
    if (policy == LeavingKeyframe::kSpread) {
      EXPECT_EQ(recorded, std::vector<int>({0, 1, 3, 4, 5}));
      EXPECT_EQ(window.Departed()[0].id, 2);
    } else {
      EXPECT_EQ(recorded, std::vector<int>({1, 2, 3, 4, 5}));
      EXPECT_EQ(window.Departed()[0].id, 0);
    }
  }
}

}  // namespace
}  // namespace pldvo
