#include "backend/odometry/brightness_change.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "core/statistics.h"

namespace pldvo {
namespace {

double PatchMean(const cv::Mat& image, const cv::Point2f& centre) {
  cv::Mat patch;
  cv::getRectSubPix(image, cv::Size(kBrightnessPatchPx, kBrightnessPatchPx), centre, patch, CV_32F);
  return cv::mean(patch)[0];
}

// The line y = gain * x + offset through the kept pairs by reduced major axis regression: the
// gain is the ratio of the spreads, not the least-squares slope, which errors in x (tracking,
// noise) would bias towards zero; errors that the exposure scales with the image do not bias it.
bool FitLine(const std::vector<double>& x, const std::vector<double>& y,
             const std::vector<bool>& keep, BrightnessChange* change) {
  double n = 0.0, sx = 0.0, sy = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    if (!keep[i]) continue;
    n += 1.0;
    sx += x[i];
    sy += y[i];
  }
  if (n < 3.0) return false;
  const double mx = sx / n, my = sy / n;
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    if (!keep[i]) continue;
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 1e-9 * n) || !(sxy > 0.0)) return false;  // no spread, or an inverted image
  change->gain = std::sqrt(syy / sxx);
  change->offset = my - change->gain * mx;
  change->pairs = static_cast<int>(n);
  return true;
}

}  // namespace

BrightnessChange FitBrightnessChange(const cv::Mat& previous, const cv::Mat& next,
                                     const std::vector<cv::Point2f>& in_previous,
                                     const std::vector<cv::Point2f>& in_next) {
  if (in_previous.size() != in_next.size()) {
    throw std::invalid_argument("FitBrightnessChange: point lists of different lengths");
  }
  std::vector<double> x, y;
  for (size_t i = 0; i < in_previous.size(); ++i) {
    x.push_back(PatchMean(previous, in_previous[i]));
    y.push_back(PatchMean(next, in_next[i]));
  }
  std::vector<bool> keep(x.size(), true);
  BrightnessChange change;
  if (!FitLine(x, y, keep, &change)) return BrightnessChange();
  std::vector<double> residuals;
  for (size_t i = 0; i < x.size(); ++i) {
    residuals.push_back(std::abs(y[i] - change.gain * x[i] - change.offset));
  }
  // 1.4826 * MAD: the standard deviation of Gaussian residuals.
  const double robust_sigma = 1.4826 * Median(residuals);
  for (size_t i = 0; i < x.size(); ++i) keep[i] = residuals[i] <= 3.0 * robust_sigma;
  BrightnessChange refit;
  return FitLine(x, y, keep, &refit) ? refit : change;
}

bool ChangesGrayLevels(const BrightnessChange& change) {
  // The change is affine, so its largest shift over [0, 255] is at an end.
  return std::max(std::abs(change.offset), std::abs((change.gain - 1.0) * 255.0 + change.offset)) >=
         1.0;
}

cv::Mat UndoBrightnessChange(const cv::Mat& next, const BrightnessChange& change) {
  cv::Mat gray;
  next.convertTo(gray, CV_8U, 1.0 / change.gain, -change.offset / change.gain);
  return gray;
}

}  // namespace pldvo
