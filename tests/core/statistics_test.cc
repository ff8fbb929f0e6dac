#include "core/statistics.h"

#include <gtest/gtest.h>

#include <vector>

namespace pldvo {
namespace {

// Every expectation is exact: the values are small binary fractions, so the sums and halves are
// computed without rounding.

TEST(StatisticsTest, MedianOfAnOddCountIsTheMiddleValue) {
  EXPECT_EQ(Median({7.0}), 7.0);
  EXPECT_EQ(Median({1.0, 2.0, 3.0}), 2.0);
  EXPECT_EQ(Median({3.0, -1.0, 2.0, 10.0, 0.5}), 2.0);  // unsorted
}

// The even-count rule: the mean of the two middle values. The lower middle value (2), the upper
// one (4) and the middle of the range ((1 + 100) / 2) each give a different answer here.
TEST(StatisticsTest, MedianOfAnEvenCountIsTheMeanOfTheTwoMiddleValues) {
  EXPECT_EQ(Median({1.0, 2.0}), 1.5);
  EXPECT_EQ(Median({1.0, 2.0, 4.0, 100.0}), 3.0);
  EXPECT_EQ(Median({100.0, 4.0, 1.0, 2.0}), 3.0);             // unsorted
  EXPECT_EQ(Median({4.0, 4.0, 1.0, 100.0, 4.0, -3.0}), 4.0);  // ties in the middle
  EXPECT_EQ(Median({-2.0, -1.0, 0.5, 8.0, 9.0, -0.5}), 0.0);  // (-0.5 + 0.5) / 2
}

TEST(StatisticsTest, MedianOfNoValuesIsZero) { EXPECT_EQ(Median({}), 0.0); }

TEST(StatisticsTest, MedianTakesItsArgumentByValue) {
  const std::vector<double> values = {5.0, 1.0, 4.0, 2.0};
  EXPECT_EQ(Median(values), 3.0);
  EXPECT_EQ(values, (std::vector<double>{5.0, 1.0, 4.0, 2.0}));  // the caller's order is kept
}

TEST(StatisticsTest, UpperMedianIsTheSampleAtRankHalfTheCount) {
  EXPECT_EQ(UpperMedian({3.0, 1.0, 2.0}), 2.0);
  // Even count: the upper middle value, where Median takes the mean of the two.
  EXPECT_EQ(UpperMedian({4.0, 1.0, 3.0, 2.0}), 3.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_EQ(UpperMedian({}), 0.0);
}

TEST(StatisticsTest, Mean) {
  EXPECT_EQ(Mean({}), 0.0);
  EXPECT_EQ(Mean({3.0}), 3.0);
  EXPECT_EQ(Mean({1.0, 2.0, 4.0, 100.0}), 26.75);
  EXPECT_EQ(Mean({-1.5, 1.5, 0.25, 0.75}), 0.25);
}

}  // namespace
}  // namespace pldvo
