// JudgeLineMatchByDepth (experiments/evaluation/line_match_ground_truth.h): exact cases on a plane
// and at a depth edge, agreement with the scene-edge judgement of
// tests/frontend/line_ground_truth.h on lowtex, and the match precision on textured, where most
// matches are between texture lines that no modelled scene edge verifies (docs/line_frontend.md).
#include "experiments/evaluation/line_match_ground_truth.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "experiments/synthetic/synthetic_sequence.h"
#include "frontend/line_frontend.h"
#include "tests/frontend/line_ground_truth.h"
#include "tests/render_cache.h"

namespace pldvo {
namespace {

PinholeCamera Camera() { return PinholeCamera{640, 480, 525.0, 525.0, 319.5, 239.5}; }

// The keyframe segment a-b on a fronto-parallel plane at depth z, moved by cur_from_ref.
LineSegment Moved(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z,
                  const SE3& cur_from_ref) {
  const PinholeCamera camera = Camera();
  return MakeLineSegment(camera.Project(cur_from_ref * (z * camera.Unproject(a))),
                         camera.Project(cur_from_ref * (z * camera.Unproject(b))), 0, 0.5);
}

SE3 SmallMotion() {
  return SE3(
      Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix(),
      Eigen::Vector3d(0.08, -0.02, 0.05));
}

TEST(JudgeLineMatchByDepthTest, PlaneCases) {
  const PinholeCamera camera = Camera();
  const cv::Mat depth(480, 640, CV_32F, cv::Scalar(2.0f));
  const Eigen::Vector2d a(150, 200), b(350, 230);
  const LineSegment ref = MakeLineSegment(a, b, 0, 0.5);
  const SE3 motion = SmallMotion();
  const LineSegment truth = Moved(a, b, 2.0, motion);
  auto judge = [&](const LineSegment& cur) {
    return JudgeLineMatchByDepth(camera, ref, depth, motion, cur);
  };
  EXPECT_EQ(judge(truth), LineMatchTruth::kCorrect);
  // A collinear piece of the same line counts (the residuals use the infinite line).
  EXPECT_EQ(judge(MakeLineSegment(truth.start, truth.midpoint(), 0, 0.5)),
            LineMatchTruth::kCorrect);
  // Within / beyond the 2 px band (the parallel texture line next to it).
  const Eigen::Vector2d n = truth.normal();
  EXPECT_EQ(judge(MakeLineSegment(truth.start + 1.5 * n, truth.end + 1.5 * n, 0, 0.5)),
            LineMatchTruth::kCorrect);
  EXPECT_EQ(judge(MakeLineSegment(truth.start + 3.0 * n, truth.end + 3.0 * n, 0, 0.5)),
            LineMatchTruth::kWrong);
  // Turned by 5 deg about its midpoint (its ends leave the 2 px band).
  const Eigen::Rotation2Dd turn(5.0 * M_PI / 180.0);
  const Eigen::Vector2d m = truth.midpoint();
  EXPECT_EQ(
      judge(MakeLineSegment(m + turn * (truth.start - m), m + turn * (truth.end - m), 0, 0.5)),
      LineMatchTruth::kWrong);
  // The same motion with the plane at 4 m instead of 2: the transfer differs by the parallax.
  EXPECT_EQ(judge(Moved(a, b, 4.0, motion)), LineMatchTruth::kWrong);
  // No depth, or most of the segment leaving the current image.
  EXPECT_EQ(
      JudgeLineMatchByDepth(camera, ref, cv::Mat(480, 640, CV_32F, cv::Scalar(0.f)), motion, truth),
      LineMatchTruth::kUnverifiable);
  const SE3 away(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));
  EXPECT_EQ(JudgeLineMatchByDepth(camera, ref, depth, away, Moved(a, b, 2.0, away)),
            LineMatchTruth::kUnverifiable);
  EXPECT_THROW(JudgeLineMatchByDepth(camera, ref, cv::Mat(480, 640, CV_8U), motion, truth),
               std::invalid_argument);
}

TEST(JudgeLineMatchByDepthTest, DepthEdgeTakesTheOccludingSide) {
  // Left of column 320 a plane at 1 m, right of it one at 3 m; the edge at x = 320 belongs to the
  // near plane (the far plane's pixels next to it are occluded in other views).
  const PinholeCamera camera = Camera();
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(3.0f));
  depth.colRange(0, 321).setTo(1.0f);
  const Eigen::Vector2d a(320, 100), b(320, 380);
  const LineSegment ref = MakeLineSegment(a, b, 0, 0.5);
  const SE3 motion(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.05, 0.0, 0.0));
  EXPECT_EQ(JudgeLineMatchByDepth(camera, ref, depth, motion, Moved(a, b, 1.0, motion)),
            LineMatchTruth::kCorrect);
  EXPECT_EQ(JudgeLineMatchByDepth(camera, ref, depth, motion, Moved(a, b, 3.0, motion)),
            LineMatchTruth::kWrong);
}

// Frames keyframe + {0, 1, 5, 10} of a 640x480 preset, processed by the default frontend.
struct Clip {
  synthetic::SyntheticSequence sequence;
  std::map<int, synthetic::RenderedFrame> rendered;
  std::map<int, LineFrame> lines;
};

Clip MakeClip(const std::string& preset, int seed) {
  synthetic::SynthOptions synth;
  synth.preset = preset;
  synth.seed = seed;
  synth.frames = 40;
#ifdef PLDVO_SANITIZE
  synth.supersampling = 1;  // CI budget under the sanitizers (docs/reliability.md)
#endif
  Clip clip{synthetic::MakeSequence(synth), {}, {}};
  // Every segment described once here: the tests match copies of these frames.
  LineFrontendOptions options;
  options.descriptor.on_demand = false;
  LineFrontend frontend{options};
  for (int keyframe : {0, 25}) {
    for (int gap : {0, 1, 5, 10}) {
      clip.rendered[keyframe + gap] = test::RenderFrameForTest(clip.sequence, keyframe + gap);
      clip.lines[keyframe + gap] = frontend.Process(clip.rendered[keyframe + gap].image);
    }
  }
  return clip;
}

struct Counts {
  int correct = 0, wrong = 0, unverifiable = 0;
  double precision() const { return static_cast<double>(correct) / (correct + wrong); }
};

// Every match of keyframe -> keyframe + gap judged by depth; with `predicted`, matched around
// the segments' true positions (the GT pose and depth), as the odometry matches around the
// tracker's prior.
template <typename Visit>
void ForEachMatch(const Clip& clip, bool predicted, Visit visit) {
  LineFrontend frontend{LineFrontendOptions()};
  for (int keyframe : {0, 25}) {
    for (int gap : {1, 5, 10}) {
      LineFrame ref = clip.lines.at(keyframe);
      LineFrame cur = clip.lines.at(keyframe + gap);
      const SE3 cur_from_ref = clip.sequence.ground_truth[keyframe + gap].world_from_cam.Inverse() *
                               clip.sequence.ground_truth[keyframe].world_from_cam;
      const PinholeCamera& camera = clip.sequence.camera;
      const cv::Mat& depth = clip.rendered.at(keyframe).depth;
      const SegmentPredictor predictor =
          predicted ? PredictorFromDepth(camera, depth, cur_from_ref) : SegmentPredictor();
      for (const LineMatch& m : frontend.Match(&ref, &cur, predictor)) {
        const LineMatchTruth truth = JudgeLineMatchByDepth(camera, ref.segments[m.ref_index], depth,
                                                           cur_from_ref, cur.segments[m.cur_index]);
        visit(keyframe, gap, m, truth);
      }
    }
  }
}

TEST(JudgeLineMatchByDepthTest, AgreesWithTheSceneEdgesOnLowtex) {
  // Where the scene-edge judgement of the frontend's acceptance test can decide, the depth
  // judgement must decide the same way.
  int agree = 0, disagree = 0, depth_only = 0;
  for (int seed : {1, 3}) {
    const Clip clip = MakeClip("lowtex", seed);
    std::map<int, std::vector<int>> edge_of_segment;
    for (const auto& [index, lines] : clip.lines) {
      const SE3& world_from_cam = clip.sequence.ground_truth[index].world_from_cam;
      const std::vector<test::GtPiece> pieces =
          test::VisibleEdgePieces(clip.sequence, world_from_cam, clip.rendered.at(index), 0.0);
      for (const LineSegment& s : lines.segments) {
        edge_of_segment[index].push_back(
            test::AssociateSegment(s, pieces, 2.0, 5.0 * M_PI / 180.0, 0.8));
      }
    }
    ForEachMatch(clip, false, [&](int keyframe, int gap, const LineMatch& m, LineMatchTruth truth) {
      const int cur = keyframe + gap;
      const test::MatchOutcome by_edges = test::JudgeMatch(
          clip.sequence, clip.lines.at(keyframe).segments[m.ref_index],
          clip.sequence.ground_truth[keyframe].world_from_cam,
          edge_of_segment[keyframe][m.ref_index], clip.lines.at(cur).segments[m.cur_index],
          clip.sequence.ground_truth[cur].world_from_cam, edge_of_segment[cur][m.cur_index]);
      if (truth == LineMatchTruth::kUnverifiable) return;
      if (by_edges == test::MatchOutcome::kUnverifiable) {
        ++depth_only;
        return;
      }
      const bool same =
          (truth == LineMatchTruth::kCorrect) == (by_edges == test::MatchOutcome::kCorrect);
      (same ? agree : disagree)++;
    });
  }
  std::printf("lowtex: the two judgements agree on %d matches, differ on %d; %d only by depth\n",
              agree, disagree, depth_only);
  ASSERT_GT(agree, 300);
  EXPECT_LE(disagree, 0.02 * (agree + disagree));
}

TEST(JudgeLineMatchByDepthTest, MatchPrecisionOnTextured) {
  // Measured: 0.947 without a prediction, 0.959 with it (lowtex: 0.975-0.992 by the scene
  // edges); the wrong matches are parallel texture lines 4-16 px off and lines crossing the true
  // one at 2-4 degrees. The bound catches a matcher that gets worse.
  std::vector<Clip> clips;
#ifdef PLDVO_SANITIZE
  // CI budget under the sanitizers (docs/reliability.md): seed 2 alone, without supersampling
  // (measured there: 0.955 / 0.956).
  clips.push_back(MakeClip("textured", 2));
#else
  for (int seed : {1, 2, 3}) clips.push_back(MakeClip("textured", seed));
#endif
  for (bool predicted : {false, true}) {
    Counts total;
    for (size_t i = 0; i < clips.size(); ++i) {
      Counts counts;
      ForEachMatch(clips[i], predicted, [&](int, int, const LineMatch&, LineMatchTruth t) {
        counts.correct += t == LineMatchTruth::kCorrect;
        counts.wrong += t == LineMatchTruth::kWrong;
        counts.unverifiable += t == LineMatchTruth::kUnverifiable;
      });
      std::printf("textured clip %zu, %s: %d correct, %d wrong, %d unverifiable; precision %.3f\n",
                  i, predicted ? "predicted" : "no prediction", counts.correct, counts.wrong,
                  counts.unverifiable, counts.precision());
      total.correct += counts.correct;
      total.wrong += counts.wrong;
      total.unverifiable += counts.unverifiable;
    }
    std::printf("textured, %s: precision %.3f\n", predicted ? "predicted" : "no prediction",
                total.precision());
    ASSERT_GT(total.correct, 400);
    EXPECT_GT(total.precision(), 0.92);
  }
}

}  // namespace
}  // namespace pldvo
