// Line segment detection on an octave pyramid (seed paper Sec. VI-A(1): LSD on two octaves).
// The detector runs on octaves first_octave .. first_octave + num_octaves - 1 of a pyramid
// built with cv::pyrDown (scale factor 2; a pixel centre x at octave k is 2^k x at octave 0,
// the convention of cv::line_descriptor::BinaryDescriptor), maps the endpoints to full
// resolution and orients each segment by its edge polarity (line_segment.h). The same edge
// found on two octaves gives two overlapping segments; LineMerger fuses them.
#ifndef PLDVO_FRONTEND_LINE_DETECTOR_H_
#define PLDVO_FRONTEND_LINE_DETECTOR_H_

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/edge_drawing.hpp>
#include <opencv2/ximgproc/fast_line_detector.hpp>
#include <vector>

#include "frontend/line_frontend_options.h"
#include "frontend/line_segment.h"

namespace pldvo {

// An 8-bit image from a frame: CV_8U is shared, CV_32F (0..255) is rounded and saturated.
// Throws std::invalid_argument for other types or multi-channel images.
cv::Mat ToGray8(const cv::Mat& image);

// Octave pyramid of an 8-bit image: octaves[0] is the image, octaves[k] = pyrDown(octaves[k-1]).
std::vector<cv::Mat> BuildOctaves(const cv::Mat& image_u8, int num_octaves);

class LineDetector {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit LineDetector(const LineDetectorOptions& options);

  // Segments of all detection octaves in full-resolution pixels, oriented by polarity,
  // unmerged. `octaves` must hold at least first_octave + num_octaves levels (BuildOctaves).
  // Not thread-safe (the OpenCV detectors keep state); use one detector per thread.
  std::vector<LineSegment> Detect(const std::vector<cv::Mat>& octaves);

  const LineDetectorOptions& options() const { return options_; }

 private:
  void DetectOctave(const cv::Mat& image, std::vector<cv::Vec4f>* raw);

  LineDetectorOptions options_;
  cv::Ptr<cv::LineSegmentDetector> lsd_;
  cv::Ptr<cv::ximgproc::EdgeDrawing> edlines_;
  cv::Ptr<cv::ximgproc::FastLineDetector> fld_;
};

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_DETECTOR_H_
