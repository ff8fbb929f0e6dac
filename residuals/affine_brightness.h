// Affine brightness transfer from the reference (keyframe) image to the current image, the
// model of DSO (Engel et al., "Direct Sparse Odometry", TPAMI 2018, eq. 4) without exposure
// times:
//
//   I_cur(tau(x)) ~ e^a I_ref(x) + b,
//
// with the log-gain a and the bias b (gray levels) of the current frame relative to the
// reference. The semi-dense VO the seed paper builds on has no such term (a = b = 0); it is
// config `tracking.problem.brightness` (docs/tracking.md, "Affine brightness"). As a parameter
// block it is double[2] = {a, b}, Euclidean. In the odometry (a, b) is relative to the current
// keyframe: a frame enters its keyframe's stereo as e^-a (I - b).
#ifndef PLDVO_RESIDUALS_AFFINE_BRIGHTNESS_H_
#define PLDVO_RESIDUALS_AFFINE_BRIGHTNESS_H_

#include <opencv2/core.hpp>

#include "core/options.h"

namespace pldvo {

constexpr int kBrightnessSize = 2;

struct AffineBrightness {
  double a = 0.0;  // log-gain
  double b = 0.0;  // bias, gray levels
  bool IsIdentity() const { return a == 0.0 && b == 0.0; }
};

// The image in the reference's brightness, e^-a (image - b), as CV_32F; `image` itself (not a
// copy) when the transfer is the identity. `image` is single-channel, 8-bit or float.
cv::Mat InReferenceBrightness(const cv::Mat& image, const AffineBrightness& brightness);

// Whether the tracking problem estimates the brightness transfer.
enum class BrightnessModel { kNone, kAffine };

inline const ChoiceNames<BrightnessModel>& BrightnessModelNames() {
  static const ChoiceNames<BrightnessModel> names = {{"none", BrightnessModel::kNone},
                                                     {"affine", BrightnessModel::kAffine}};
  return names;
}

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_AFFINE_BRIGHTNESS_H_
