// Image pyramid of float intensities with precomputed gradients, stored per level as one
// interleaved CV_32FC3 image [I, dI/dx, dI/dy] so that one bilinear lookup yields the
// intensity and its gradient (as in DSO's dI arrays). Level l+1 is the 2x2 average of level l;
// gradients are central differences (zero on the one-pixel border). The intensity of each level
// is also kept as a contiguous single-channel CV_32F plane, the layout ceres::Grid2D<float>
// needs for bicubic sampling (residuals/photometric_residual.h).
#ifndef PLDVO_CORE_IMAGE_PYRAMID_H_
#define PLDVO_CORE_IMAGE_PYRAMID_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace pldvo {

class ImagePyramid {
 public:
  ImagePyramid() = default;
  // `image` is 8-bit or float single-channel; intensities keep their 0..255 scale.
  ImagePyramid(const cv::Mat& image, int num_levels);

  int num_levels() const { return static_cast<int>(levels_.size()); }
  int width(int level) const { return levels_[level].cols; }
  int height(int level) const { return levels_[level].rows; }
  // The interleaved [I, Ix, Iy] image of a level.
  const cv::Mat& level(int level) const { return levels_[level]; }
  // Intensity alone as a CV_32F image (a copy).
  cv::Mat Intensity(int level) const;
  // The stored intensity plane of a level: row-major, continuous, width(level) floats per row.
  const float* IntensityData(int level) const { return intensity_levels_[level].ptr<float>(); }

  // True when bilinear sampling at (x, y) stays inside the image.
  bool CanSample(int level, double x, double y) const {
    return x >= 0.0 && y >= 0.0 && x < levels_[level].cols - 1 && y < levels_[level].rows - 1;
  }
  // Bilinear [I, Ix, Iy] at (x, y). Requires CanSample(level, x, y).
  Eigen::Vector3f Sample(int level, double x, double y) const {
    const cv::Mat& image = levels_[level];
    const int ix = static_cast<int>(x);
    const int iy = static_cast<int>(y);
    const float dx = static_cast<float>(x - ix);
    const float dy = static_cast<float>(y - iy);
    const float* row0 = image.ptr<float>(iy) + 3 * ix;
    const float* row1 = image.ptr<float>(iy + 1) + 3 * ix;
    const Eigen::Map<const Eigen::Vector3f> p00(row0), p01(row0 + 3), p10(row1), p11(row1 + 3);
    return (1.f - dy) * ((1.f - dx) * p00 + dx * p01) + dy * ((1.f - dx) * p10 + dx * p11);
  }
  // Bilinear I alone at (x, y), from the intensity plane: Sample(level, x, y)[0] bit for bit at
  // a third of the work (the stereo SSDs read intensities only). Requires CanSample(level, x, y).
  float SampleIntensity(int level, double x, double y) const {
    const cv::Mat& plane = intensity_levels_[level];
    const int ix = static_cast<int>(x);
    const int iy = static_cast<int>(y);
    const float dx = static_cast<float>(x - ix);
    const float dy = static_cast<float>(y - iy);
    const float* row0 = plane.ptr<float>(iy) + ix;
    const float* row1 = plane.ptr<float>(iy + 1) + ix;
    return (1.f - dy) * ((1.f - dx) * row0[0] + dx * row0[1]) +
           dy * ((1.f - dx) * row1[0] + dx * row1[1]);
  }

 private:
  std::vector<cv::Mat> levels_;
  std::vector<cv::Mat> intensity_levels_;  // CV_32F, continuous
};

}  // namespace pldvo

#endif  // PLDVO_CORE_IMAGE_PYRAMID_H_
