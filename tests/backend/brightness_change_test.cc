// The exposure change fitted to tracked patches (brightness_change.h), on an image moved by a
// known sub-pixel shift with a known gain and offset.
#include "backend/odometry/brightness_change.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <vector>

namespace pldvo {
namespace {

// Surfaces of different brightness: 60 random rectangles of gray levels 30-220, slightly blurred.
cv::Mat Texture(int seed) {
  cv::Mat image(240, 320, CV_32F, cv::Scalar(120.0));
  cv::RNG rng(seed);
  for (int i = 0; i < 60; ++i) {
    const int x = rng.uniform(0, 300), y = rng.uniform(0, 220);
    const cv::Rect rect(x, y, rng.uniform(10, 320 - x), rng.uniform(10, 240 - y));
    image(rect).setTo(rng.uniform(30.0, 220.0));
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  return image;
}

// `image` moved by (dx, dy) px: pixel p of the result shows p - (dx, dy) of `image`.
cv::Mat Shifted(const cv::Mat& image, double dx, double dy) {
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat moved;
  cv::warpAffine(image, moved, shift, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return moved;
}

struct Pairs {
  std::vector<cv::Point2f> previous, next;
};

// A grid of points and where the shift moves them; every `wrong_every`-th pair points elsewhere.
Pairs GridPairs(double dx, double dy, int wrong_every) {
  Pairs pairs;
  int i = 0;
  for (int y = 20; y < 220; y += 10) {
    for (int x = 20; x < 300; x += 10, ++i) {
      pairs.previous.emplace_back(x, y);
      const bool wrong = wrong_every > 0 && i % wrong_every == 0;
      pairs.next.emplace_back(wrong ? cv::Point2f(300 - x, 240 - y) : cv::Point2f(x + dx, y + dy));
    }
  }
  return pairs;
}

TEST(BrightnessChangeTest, RecoversGainAndOffsetDespiteWrongTracks) {
  const cv::Mat previous = Texture(3);
  constexpr double kGain = 0.72, kOffset = 13.5, kDx = 2.3, kDy = -1.6;
  const cv::Mat next = Shifted(previous, kDx, kDy) * kGain + kOffset;
  // One pair in five wrong (it points elsewhere in the frame): the refit leaves them out.
  const Pairs pairs = GridPairs(kDx, kDy, 5);
  const BrightnessChange change = FitBrightnessChange(previous, next, pairs.previous, pairs.next);
  EXPECT_NEAR(change.gain, kGain, 2e-3);
  EXPECT_NEAR(change.offset, kOffset, 0.3);
  EXPECT_GE(change.pairs, static_cast<int>(0.5 * pairs.previous.size()));
  EXPECT_LE(change.pairs, static_cast<int>(0.85 * pairs.previous.size()));
  EXPECT_TRUE(ChangesGrayLevels(change));

  // Undone, the frame shows the previous one's intensities to within the 8-bit rounding.
  const cv::Mat undone = UndoBrightnessChange(next, change);
  ASSERT_EQ(undone.type(), CV_8U);
  cv::Mat expected, difference;
  Shifted(previous, kDx, kDy).convertTo(expected, CV_8U);
  cv::absdiff(undone, expected, difference);
  EXPECT_LE(cv::mean(difference)[0], 0.6);
}

TEST(BrightnessChangeTest, SteadyExposureIsNoChange) {
  const cv::Mat previous = Texture(4);
  const Pairs pairs = GridPairs(1.7, 0.4, 0);
  const BrightnessChange change =
      FitBrightnessChange(previous, Shifted(previous, 1.7, 0.4), pairs.previous, pairs.next);
  EXPECT_NEAR(change.gain, 1.0, 1e-3);
  EXPECT_NEAR(change.offset, 0.0, 0.2);
  EXPECT_FALSE(ChangesGrayLevels(change));
  // One gray level at either end of the range is a change.
  EXPECT_TRUE(ChangesGrayLevels({1.0, -1.0, 0}));
  EXPECT_TRUE(ChangesGrayLevels({1.0 + 1.01 / 255.0, 0.0, 0}));
  EXPECT_FALSE(ChangesGrayLevels({1.0 + 0.9 / 255.0, 0.0, 0}));
}

TEST(BrightnessChangeTest, TooFewOrFlatPatchesAreNoChange) {
  const cv::Mat previous = Texture(5);
  const cv::Mat flat(previous.size(), CV_32F, cv::Scalar(90.0));
  const Pairs pairs = GridPairs(0.0, 0.0, 0);
  const std::vector<cv::Point2f> two(pairs.previous.begin(), pairs.previous.begin() + 2);
  for (const BrightnessChange& change :
       {FitBrightnessChange(previous, previous * 2.0, two, two),
        FitBrightnessChange(flat, flat, pairs.previous, pairs.next),
        FitBrightnessChange(previous, 255.0 - previous, pairs.previous, pairs.next)}) {
    EXPECT_EQ(change.gain, 1.0);
    EXPECT_EQ(change.offset, 0.0);
    EXPECT_EQ(change.pairs, 0);
  }
  EXPECT_THROW(FitBrightnessChange(previous, previous, two, pairs.next), std::invalid_argument);
}

}  // namespace
}  // namespace pldvo
