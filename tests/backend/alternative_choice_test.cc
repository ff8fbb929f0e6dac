// BetterAlternative and AlternativeMayCompete (backend/odometry/alternative_choice.h): which
// retried tracking result wins.
#include "backend/odometry/alternative_choice.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pldvo {
namespace {

using Choice = OdometryOptions::AlternativeChoice;

TrackingResult Result(int inlier_rows, int photometric_valid_rows, double correlation,
                      const SE3& cur_from_ref = SE3()) {
  TrackingResult result;
  result.cur_from_ref = cur_from_ref;
  result.status = TrackingStatus::kConverged;
  LevelResult finest;
  finest.inlier_rows = inlier_rows;
  finest.photometric_valid_rows = photometric_valid_rows;
  finest.intensity_correlation = correlation;
  result.levels = {LevelResult(), finest};
  result.intensity_correlation = correlation;
  return result;
}

// Frame 129 of contrast 0.5x seed 2, map 2 (docs/odometry.md, "Alternative initial guesses"):
// the constant-velocity guess converged with 6536 inlier rows at correlation 0.978; the guess
// rotated by 2 deg about x reached 7103 inlier rows at correlation 0.532, 60 deg from the true
// rotation. The inlier rows alone chose it; weighted by the correlation they do not.
TEST(AlternativeChoiceTest, CorrelationOutweighsInlierRowsOnAWrongPose) {
  const TrackingResult right = Result(6536, 6000, 0.978);
  const TrackingResult wrong = Result(7103, 6500, 0.532);
  EXPECT_TRUE(BetterAlternative(wrong, right, Choice::kInlierRows));
  EXPECT_FALSE(BetterAlternative(wrong, right, Choice::kCorrelatedInlierRows));
  EXPECT_TRUE(BetterAlternative(right, wrong, Choice::kCorrelatedInlierRows));
  EXPECT_DOUBLE_EQ(AlternativeScore(right, Choice::kCorrelatedInlierRows), 6536 * 0.978);
  EXPECT_FALSE(BetterAlternative(wrong, right, Choice::kRowsAndCorrelation));
}

// rows_and_correlation: an alternative wins only where it is better in both; a near tie in
// inlier rows at a lower correlation, or a higher correlation on fewer rows, keeps the first.
TEST(AlternativeChoiceTest, RowsAndCorrelationNeedsBothToBeBetter) {
  const TrackingResult first = Result(5000, 4800, 0.90);
  EXPECT_TRUE(BetterAlternative(Result(5001, 4800, 0.90), first, Choice::kRowsAndCorrelation));
  EXPECT_FALSE(BetterAlternative(Result(5200, 5000, 0.89), first, Choice::kRowsAndCorrelation));
  EXPECT_FALSE(BetterAlternative(Result(4999, 4900, 0.99), first, Choice::kRowsAndCorrelation));
  EXPECT_FALSE(BetterAlternative(first, first, Choice::kRowsAndCorrelation));
  // The correlated score would take the second (5200 x 0.89 > 5000 x 0.90), this choice not.
  EXPECT_TRUE(BetterAlternative(Result(5200, 5000, 0.89), first, Choice::kCorrelatedInlierRows));
  // Without photometric rows on either side the inlier rows decide.
  EXPECT_TRUE(
      BetterAlternative(Result(300, 0, 0.0), Result(200, 1000, 0.9), Choice::kRowsAndCorrelation));
  // A result without levels never wins and always loses.
  EXPECT_FALSE(BetterAlternative(TrackingResult(), first, Choice::kRowsAndCorrelation));
  TrackingResult empty;
  empty.status = TrackingStatus::kConverged;
  EXPECT_TRUE(BetterAlternative(first, empty, Choice::kRowsAndCorrelation));
}

SE3 Motion(double rotation_deg, const Eigen::Vector3d& translation) {
  return SE3(ExpSO3(rotation_deg * M_PI / 180.0 * Eigen::Vector3d::UnitX()), translation);
}

// Frame 123 of checkerboard seed 5, map 1 (docs/odometry.md, "Alternative initial guesses"): the
// prior moved the camera 0.67 deg and 4.7 mm over the frame, at a mean inverse depth of 0.723;
// the first result had 2409 inlier rows at correlation 0.973; the guess rotated 2 deg about x
// ended 72 mm from it, one period of the pattern, with 2807 rows at 0.860. The gate keeps it out.
TEST(AlternativeChoiceTest, MotionGateKeepsOutANeighbouringPeriodOfAPattern) {
  const double mean_idepth = 0.723;
  const SE3 prior_step = Motion(0.667, Eigen::Vector3d(0.0047, 0.0, 0.0));
  const TrackingResult first = Result(2409, 4204, 0.973);
  const TrackingResult period = Result(2807, 4188, 0.860, Motion(0.020, {0.0, 0.0723, 0.0}));
  // Image motion: 0.02 deg + 72.3 mm * 0.723 = 0.0526 rad against 0.0150 for the step.
  EXPECT_NEAR(ImageMotion(period.cur_from_ref, mean_idepth), 0.0526, 1e-4);
  EXPECT_NEAR(ImageMotion(prior_step, mean_idepth), 0.0150, 1e-4);
  EXPECT_TRUE(BeyondPriorStep(period, first, prior_step, mean_idepth));
  EXPECT_FALSE(AlternativeMayCompete(period, first, prior_step, mean_idepth,
                                     Choice::kMotionGatedInlierRows));
  // The other choices let it compete; by the inlier rows it would win.
  EXPECT_TRUE(AlternativeMayCompete(period, first, prior_step, mean_idepth, Choice::kInlierRows));
  EXPECT_TRUE(BetterAlternative(period, first, Choice::kMotionGatedInlierRows));
  // Beyond the step it competes with a correlation no lower, and whenever the first is lost.
  const TrackingResult correlated = Result(2807, 4188, 0.973, period.cur_from_ref);
  EXPECT_TRUE(AlternativeMayCompete(correlated, first, prior_step, mean_idepth,
                                    Choice::kMotionGatedInlierRows));
  TrackingResult lost = first;
  lost.status = TrackingStatus::kLost;
  EXPECT_TRUE(
      AlternativeMayCompete(period, lost, prior_step, mean_idepth, Choice::kMotionGatedInlierRows));
}

// Frame 99 of boxes seed 2, map 1: the alternative ended 0.02 deg and 0.2 mm from the first result
// (the same minimum, better converged) where the prior moved 0.28 deg and 8.6 mm: it competes by
// its inlier rows alone. Frame 2 of pivot seed 3, map 3, turning about a point behind the camera:
// 7.8 mm from the first result where the prior moved 0.3 mm, but 0.35 deg where it turned
// 0.90 deg; in image motion (mean inverse depth 0.866) 0.0128 against 0.0159 rad: it competes.
TEST(AlternativeChoiceTest, MotionGateLetsAnAlternativeWithinTheStepCompete) {
  struct Case {
    const char* frame;
    SE3 prior_step;
    TrackingResult first;
    TrackingResult alternative;
    double mean_idepth;
    bool competes;
  };
  const Case cases[] = {
      {"boxes s2 frame 99", Motion(0.277, {0.0, 0.0, 0.0086}), Result(5481, 6160, 0.8944),
       Result(5492, 6170, 0.8941, Motion(0.019, {0.0002, 0.0, 0.0})), 1.357, true},
      {"pivot s3 frame 2", Motion(0.895, {0.0003, 0.0, 0.0}), Result(3742, 3900, 0.991),
       Result(3766, 3910, 0.961, Motion(0.346, {0.0078, 0.0, 0.0})), 0.866, true},
      // Twice as far it would not.
      {"pivot s3 frame 2, twice as far", Motion(0.895, {0.0003, 0.0, 0.0}),
       Result(3742, 3900, 0.991), Result(3766, 3910, 0.961, Motion(0.692, {0.0156, 0.0, 0.0})),
       0.866, false},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(BeyondPriorStep(c.alternative, c.first, c.prior_step, c.mean_idepth), !c.competes)
        << c.frame;
    EXPECT_EQ(AlternativeMayCompete(c.alternative, c.first, c.prior_step, c.mean_idepth,
                                    Choice::kMotionGatedInlierRows),
              c.competes)
        << c.frame;
  }
}

TEST(AlternativeChoiceTest, LostLosesAndLinesOnlyUsesTheInlierRows) {
  TrackingResult lost = Result(9000, 8000, 0.99);
  lost.status = TrackingStatus::kLost;
  const TrackingResult tracked = Result(100, 90, 0.5);
  for (const Choice choice : {Choice::kInlierRows, Choice::kCorrelatedInlierRows,
                              Choice::kRowsAndCorrelation, Choice::kMotionGatedInlierRows}) {
    EXPECT_TRUE(BetterAlternative(tracked, lost, choice));
    EXPECT_FALSE(BetterAlternative(lost, tracked, choice));
  }
  // Lines only (no photometric rows, no correlation): the inlier rows decide either way.
  EXPECT_EQ(AlternativeScore(Result(300, 0, 0.0), Choice::kCorrelatedInlierRows), 300.0);
  EXPECT_TRUE(
      BetterAlternative(Result(300, 0, 0.0), Result(200, 0, 0.0), Choice::kCorrelatedInlierRows));
  // A negative correlation counts as none.
  EXPECT_EQ(AlternativeScore(Result(300, 300, -0.2), Choice::kCorrelatedInlierRows), 0.0);
}

}  // namespace
}  // namespace pldvo
