// The exposure change between two frames, from the patches around corners tracked between them
// (docs/bootstrap.md, "Why the exposure matching"). LK has no gain term: an auto-exposure step
// between frames drags its tracks, so the two-view bootstrap maps each frame into the previous
// one's intensities before it tracks the corners into it.
#ifndef PLDVO_BACKEND_ODOMETRY_BRIGHTNESS_CHANGE_H_
#define PLDVO_BACKEND_ODOMETRY_BRIGHTNESS_CHANGE_H_

#include <opencv2/core.hpp>
#include <vector>

namespace pldvo {

// next = gain * previous + offset, in gray levels.
struct BrightnessChange {
  double gain = 1.0;
  double offset = 0.0;
  int pairs = 0;  // patch pairs the fit kept
};

// Side of the square patch whose mean intensity is compared: large enough that a tracking error
// of a pixel moves the mean little, small enough that the patch is one surface.
constexpr int kBrightnessPatchPx = 11;

// Fits the change to the mean intensities of the patches around corresponding points
// (`in_previous[i]` in `previous`, `in_next[i]` in `next`, single-channel): a line through the
// pairs (reduced major axis), then once more without the pairs farther from the line than three
// robust standard deviations (occlusions, wrong tracks). Fewer than three pairs, or patches of one
// intensity: no change.
BrightnessChange FitBrightnessChange(const cv::Mat& previous, const cv::Mat& next,
                                     const std::vector<cv::Point2f>& in_previous,
                                     const std::vector<cv::Point2f>& in_next);

// Whether undoing the change moves a gray level of [0, 255] by one or more. Below that it is
// within the 8-bit quantisation, and the frame is tracked as it is: where the exposure is steady,
// the tracks stay those of plain LK.
bool ChangesGrayLevels(const BrightnessChange& change);

// `next` mapped into the intensities of the frame the change was fitted against, as 8-bit gray.
cv::Mat UndoBrightnessChange(const cv::Mat& next, const BrightnessChange& change);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_BRIGHTNESS_CHANGE_H_
