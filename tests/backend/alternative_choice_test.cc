// BetterAlternative (backend/odometry/alternative_choice.h): which retried tracking result wins.
#include "backend/odometry/alternative_choice.h"

#include <gtest/gtest.h>

namespace pldvo {
namespace {

using Choice = OdometryOptions::AlternativeChoice;

TrackingResult Result(int inlier_rows, int photometric_valid_rows, double correlation) {
  TrackingResult result;
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

TEST(AlternativeChoiceTest, LostLosesAndLinesOnlyUsesTheInlierRows) {
  TrackingResult lost = Result(9000, 8000, 0.99);
  lost.status = TrackingStatus::kLost;
  const TrackingResult tracked = Result(100, 90, 0.5);
  for (const Choice choice :
       {Choice::kInlierRows, Choice::kCorrelatedInlierRows, Choice::kRowsAndCorrelation}) {
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
