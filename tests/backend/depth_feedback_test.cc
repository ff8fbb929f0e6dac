// The windowed BA's feedback into the current keyframe's depth filter (docs/windowed_ba.md,
// "Feedback"): DepthMapper::ApplyIdepthCorrections (the optimised points' shifts, the rigid
// re-expression of the other hypotheses, warp_current_map, and their scaling to the BA's scale,
// scale_current_map) against the closed form on a keyframe of known depth, and the scale that
// WindowedBAKeyframes::Apply measures from a result.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "backend/mapping/depth_mapper.h"
#include "backend/odometry/windowed_ba_keyframes.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {
namespace {

constexpr int kRow = 120;  // the edge's row, through the principal point
constexpr double kDepth = 2.0;
constexpr double kIdepthVar = 0.01;

// A 320x240 keyframe whose only hypotheses are the pixels x in [40, 280) of one edge on row 120,
// all at depth 2 m with variance 0.01 (1/m)^2 (float storage: compared to 1e-6 relative).
const PinholeCamera kCamera{320, 240, 250.0, 250.0, 160.0, 120.0};

DepthMapper KeyframeOfKnownDepth() {
  const PinholeCamera& camera = kCamera;
  DepthMapper mapper(camera, MappingOptions());
  const cv::Mat image(camera.height, camera.width, CV_32F, cv::Scalar(100.0f));
  EdgeTrace edges;
  edges.id_map = cv::Mat(camera.height, camera.width, CV_32S, cv::Scalar(-1));
  for (int x = 40; x < 280; ++x) edges.id_map.at<int>(kRow, x) = 0;
  const cv::Mat depth(camera.height, camera.width, CV_32F, cv::Scalar(kDepth));
  mapper.InitializeKeyframeFromDepth(image, edges, depth, kIdepthVar);
  return mapper;
}

int Index(const DepthMapper& mapper, int x) { return mapper.depth_map().Index(x, kRow); }

TEST(DepthFeedbackTest, ShiftsTheCorrectedHypothesesOnly) {
  DepthMapper mapper = KeyframeOfKnownDepth();
  const std::vector<IdepthCorrection> corrections = {{Index(mapper, 100), 0.05},
                                                     {Index(mapper, 200), -0.1}};
  EXPECT_EQ(mapper.ApplyIdepthCorrections(corrections), 2);
  const SemiDenseDepthMap& map = mapper.depth_map();
  EXPECT_NEAR(map.idepth(Index(mapper, 100)), 0.55, 1e-6);
  EXPECT_NEAR(map.idepth(Index(mapper, 200)), 0.4, 1e-6);
  EXPECT_NEAR(map.idepth_var(Index(mapper, 100)), kIdepthVar, 1e-9);  // variance kept
  EXPECT_NEAR(map.idepth(Index(mapper, 150)), 0.5, 1e-7);             // not corrected
}

TEST(DepthFeedbackTest, ScalesTheOtherHypothesesToTheBAScale) {
  DepthMapper mapper = KeyframeOfKnownDepth();
  const std::vector<IdepthCorrection> corrections = {{Index(mapper, 100), 0.05}};
  // 240 pixels of the edge: the corrected one shifted, the 239 others scaled.
  EXPECT_EQ(mapper.ApplyIdepthCorrections(corrections, nullptr, 0.8), 240);
  const SemiDenseDepthMap& map = mapper.depth_map();
  EXPECT_NEAR(map.idepth(Index(mapper, 100)), 0.55, 1e-6);  // its own correction, not scaled
  for (int x : {40, 150, 279}) {
    EXPECT_NEAR(map.idepth(Index(mapper, x)), 0.8 * 0.5, 1e-6) << x;
    EXPECT_NEAR(map.idepth_var(Index(mapper, x)), 0.8 * 0.8 * kIdepthVar, 1e-8) << x;
  }
  EXPECT_THROW(mapper.ApplyIdepthCorrections({}, nullptr, 0.0), std::invalid_argument);
  EXPECT_THROW(mapper.ApplyIdepthCorrections({}, nullptr, std::nan("")), std::invalid_argument);
}

// A keyframe moved 0.3 m back along its axis: at the principal point the point at depth 2 is at
// depth 2.3 (d' = d / (1 + t_z d)); the scale then applies to the moved depth.
TEST(DepthFeedbackTest, WarpsThenScalesTheOtherHypotheses) {
  const SE3 new_from_old(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, 0.0, 0.3));
  DepthMapper warped = KeyframeOfKnownDepth();
  warped.ApplyIdepthCorrections({}, &new_from_old);
  const int centre = Index(warped, 160);
  EXPECT_NEAR(warped.depth_map().idepth(centre), 1.0 / 2.3, 1e-6);
  // V' = (c / (c + t_z d)^2)^2 V with c = 1, c + t_z d = 1.15.
  EXPECT_NEAR(warped.depth_map().idepth_var(centre), kIdepthVar / std::pow(1.15, 4), 1e-8);

  DepthMapper both = KeyframeOfKnownDepth();
  both.ApplyIdepthCorrections({}, &new_from_old, 1.25);
  EXPECT_NEAR(both.depth_map().idepth(centre), 1.25 / 2.3, 1e-6);
  EXPECT_NEAR(both.depth_map().idepth_var(centre), 1.25 * 1.25 * kIdepthVar / std::pow(1.15, 4),
              1e-8);
}

// Two recorded keyframes with the 240 points above; a result refines n of keyframe 1's points to
// ratio x their input (and 5 of them to 3x, outliers of the median). The scale is the median
// ratio of the keyframe asked for; with fewer than kMinScalePoints points it is 1.
double ScaleOfResult(int n, double ratio, int scale_of) {
  const DepthMapper mapper = KeyframeOfKnownDepth();
  const cv::Mat image(kCamera.height, kCamera.width, CV_32F, cv::Scalar(100.0f));
  WindowedBAKeyframes keyframes(kCamera, 5);
  WindowedBAResult result;
  for (int id = 0; id < 2; ++id) {
    const SE3 world_from_kf(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1 * id, 0.0, 0.0));
    keyframes.AddKeyframe(id, id, 0.1 * id, world_from_kf, image, {}, {}, AffineBrightness());
    EXPECT_TRUE(keyframes.SetPoints(id, mapper.depth_map()));
    result.keyframes.push_back({id, world_from_kf.Inverse(), AffineBrightness()});
  }
  keyframes.Remember(-1, keyframes.MakeWindow());
  result.summary.initial_cost = 2.0;
  result.summary.final_cost = 1.0;
  for (int i = 0; i < n; ++i) result.points.push_back({1, i, ratio * 0.5});
  for (int i = n; i < n + 5; ++i) result.points.push_back({1, i, 3.0 * 0.5});
  std::vector<IdepthCorrection> corrections;
  double scale = 0.0;
  EXPECT_TRUE(keyframes.Apply(result, scale_of, &corrections, &scale));
  EXPECT_EQ(corrections.size(), scale_of == 1 ? static_cast<size_t>(n + 5) : 0u);
  return scale;
}

TEST(DepthFeedbackTest, ScaleIsTheMedianRatioOfTheKeyframesOptimisedPoints) {
  EXPECT_NEAR(ScaleOfResult(40, 0.8, 1), 0.8, 1e-6);  // 40 at 0.8 and 5 at 3: the median 0.8
  EXPECT_EQ(ScaleOfResult(40, 0.8, 0), 1.0);          // keyframe 0 has no optimised point
  EXPECT_EQ(ScaleOfResult(WindowedBAKeyframes::kMinScalePoints - 6, 0.8, 1), 1.0);
}

}  // namespace
}  // namespace pldvo
