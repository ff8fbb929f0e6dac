#include "core/image_pyramid.h"

#include <gtest/gtest.h>

namespace pldvo {
namespace {

// A linear ramp I = a x + b y + c: bilinear interpolation and central differences are exact.
cv::Mat Ramp(int width, int height, double a, double b, double c) {
  cv::Mat image(height, width, CV_32F);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.at<float>(y, x) = static_cast<float>(a * x + b * y + c);
  return image;
}

TEST(ImagePyramid, LevelsHalveTheSize) {
  const ImagePyramid pyramid(cv::Mat(480, 640, CV_8U, cv::Scalar(7)), 4);
  ASSERT_EQ(pyramid.num_levels(), 4);
  EXPECT_EQ(pyramid.width(3), 80);
  EXPECT_EQ(pyramid.height(3), 60);
  EXPECT_FLOAT_EQ(pyramid.Sample(3, 10.5, 20.25)[0], 7.f);
}

TEST(ImagePyramid, BilinearSampleOfARampIsExact) {
  const ImagePyramid pyramid(Ramp(64, 48, 1.5, -0.75, 100.0), 3);
  for (int level = 0; level < 3; ++level) {
    // Averaging 2x2 blocks keeps a ramp a ramp, with slopes doubled per level in that level's
    // pixels: x_l = (x_0 + 0.5) / 2^l - 0.5.
    const double scale = 1 << level;
    const double x = 5.3, y = 7.8;
    const double x0 = (x + 0.5) * scale - 0.5, y0 = (y + 0.5) * scale - 0.5;
    const Eigen::Vector3f sample = pyramid.Sample(level, x, y);
    EXPECT_NEAR(sample[0], 1.5 * x0 - 0.75 * y0 + 100.0, 1e-3);
    EXPECT_NEAR(sample[1], 1.5 * scale, 1e-4);
    EXPECT_NEAR(sample[2], -0.75 * scale, 1e-4);
  }
}

TEST(ImagePyramid, IntensityPlaneIsContiguousAndEqualsChannelZero) {
  // A region of interest (not continuous in memory) as input: the planes must still be
  // contiguous row-major, width floats per row, as ceres::Grid2D reads them.
  const cv::Mat full = Ramp(80, 60, 0.7, 1.3, 5.0);
  const ImagePyramid pyramid(full(cv::Rect(3, 2, 64, 48)), 3);
  for (int level = 0; level < pyramid.num_levels(); ++level) {
    const float* plane = pyramid.IntensityData(level);
    const cv::Mat& interleaved = pyramid.level(level);
    const cv::Mat copy = pyramid.Intensity(level);
    for (int y = 0; y < pyramid.height(level); ++y) {
      for (int x = 0; x < pyramid.width(level); ++x) {
        const float value = plane[y * pyramid.width(level) + x];
        EXPECT_EQ(value, interleaved.ptr<float>(y)[3 * x]) << level << " " << x << " " << y;
        EXPECT_EQ(value, copy.at<float>(y, x));
      }
    }
  }
}

TEST(ImagePyramid, SampleIntensityIsSampleChannelZeroBitForBit) {
  cv::Mat noise(48, 64, CV_32F);
  cv::randu(noise, 0.0, 255.0);
  const ImagePyramid pyramid(noise, 3);
  cv::RNG rng(7);
  for (int level = 0; level < pyramid.num_levels(); ++level) {
    for (int i = 0; i < 500; ++i) {
      const double x = rng.uniform(0.0, pyramid.width(level) - 1.0);
      const double y = rng.uniform(0.0, pyramid.height(level) - 1.0);
      ASSERT_TRUE(pyramid.CanSample(level, x, y));
      EXPECT_EQ(pyramid.SampleIntensity(level, x, y), pyramid.Sample(level, x, y)[0])
          << level << " " << x << " " << y;
    }
  }
}

TEST(ImagePyramid, CanSampleGuardsTheBorder) {
  const ImagePyramid pyramid(cv::Mat(10, 20, CV_8U, cv::Scalar(0)), 1);
  EXPECT_TRUE(pyramid.CanSample(0, 0.0, 0.0));
  EXPECT_TRUE(pyramid.CanSample(0, 18.99, 8.99));
  EXPECT_FALSE(pyramid.CanSample(0, 19.0, 5.0));
  EXPECT_FALSE(pyramid.CanSample(0, -0.01, 5.0));
}

}  // namespace
}  // namespace pldvo
