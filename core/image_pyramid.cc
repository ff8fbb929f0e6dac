#include "core/image_pyramid.h"

#include <glog/logging.h>

#include <opencv2/imgproc.hpp>

namespace pldvo {
namespace {

// Interleaves intensity and its central-difference gradients.
cv::Mat WithGradients(const cv::Mat& intensity) {
  cv::Mat interleaved(intensity.size(), CV_32FC3, cv::Scalar::all(0));
  for (int y = 0; y < intensity.rows; ++y) {
    const float* row = intensity.ptr<float>(y);
    float* out = interleaved.ptr<float>(y);
    for (int x = 0; x < intensity.cols; ++x) out[3 * x] = row[x];
    if (y == 0 || y == intensity.rows - 1) continue;
    const float* up = intensity.ptr<float>(y - 1);
    const float* down = intensity.ptr<float>(y + 1);
    for (int x = 1; x < intensity.cols - 1; ++x) {
      out[3 * x + 1] = 0.5f * (row[x + 1] - row[x - 1]);
      out[3 * x + 2] = 0.5f * (down[x] - up[x]);
    }
  }
  return interleaved;
}

}  // namespace

ImagePyramid::ImagePyramid(const cv::Mat& image, int num_levels) {
  CHECK(!image.empty()) << "ImagePyramid: empty image";
  CHECK_EQ(image.channels(), 1) << "ImagePyramid: expects a single-channel image";
  CHECK_GE(num_levels, 1);
  cv::Mat intensity;
  image.convertTo(intensity, CV_32F);
  if (!intensity.isContinuous()) intensity = intensity.clone();
  levels_.reserve(num_levels);
  intensity_levels_.reserve(num_levels);
  for (int level = 0; level < num_levels; ++level) {
    levels_.push_back(WithGradients(intensity));
    intensity_levels_.push_back(intensity);
    if (level + 1 == num_levels || intensity.cols < 4 || intensity.rows < 4) break;
    cv::Mat half(intensity.rows / 2, intensity.cols / 2, CV_32F);
    for (int y = 0; y < half.rows; ++y) {
      const float* r0 = intensity.ptr<float>(2 * y);
      const float* r1 = intensity.ptr<float>(2 * y + 1);
      float* out = half.ptr<float>(y);
      for (int x = 0; x < half.cols; ++x) {
        out[x] = 0.25f * (r0[2 * x] + r0[2 * x + 1] + r1[2 * x] + r1[2 * x + 1]);
      }
    }
    intensity = half;
  }
}

cv::Mat ImagePyramid::Intensity(int level) const { return intensity_levels_[level].clone(); }

}  // namespace pldvo
