#include "residuals/affine_brightness.h"

#include <cmath>

namespace pldvo {

cv::Mat InReferenceBrightness(const cv::Mat& image, const AffineBrightness& brightness) {
  if (brightness.IsIdentity()) return image;
  const double inverse_gain = std::exp(-brightness.a);
  cv::Mat corrected;
  image.convertTo(corrected, CV_32F, inverse_gain, -inverse_gain * brightness.b);
  return corrected;
}

}  // namespace pldvo
