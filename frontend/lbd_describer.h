// LBD binary descriptors (Zhang & Koch, "An efficient and robust line segment matching
// approach based on LBD descriptor and pairwise geometric consistency", JVCIR 2013) of our
// segments through cv::line_descriptor::BinaryDescriptor::compute. We build the KeyLines
// ourselves: class_id = segment index (unique, so BinaryDescriptor's scale-space table keeps one
// line per class), octave = the description octave, endpoints at full resolution and in that
// octave (x / 2^octave: BinaryDescriptor's octave images are successive cv::pyrDown of the
// Gaussian-blurred image, the same scale factor 2 as our detection pyramid), angle =
// atan2(d_y, d_x) of the polarity-oriented direction and numOfPixels = the octave length (the
// length of the support region). Each descriptor is 32 bytes (256 bits, Hamming distance).
#ifndef PLDVO_FRONTEND_LBD_DESCRIBER_H_
#define PLDVO_FRONTEND_LBD_DESCRIBER_H_

#include <opencv2/core.hpp>
#include <opencv2/line_descriptor.hpp>
#include <vector>

#include "frontend/line_frontend_options.h"
#include "frontend/line_segment.h"

namespace pldvo {

class LbdDescriber {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit LbdDescriber(const LineDescriptorOptions& options);

  // Descriptors (segments.size() x 32, CV_8U; row i describes segments[i]) on the 8-bit
  // full-resolution image. Not thread-safe (BinaryDescriptor keeps its pyramid as state).
  cv::Mat Describe(const cv::Mat& image_u8, const std::vector<LineSegment>& segments);

  // Describes segments[rows[k]] into row rows[k] of `descriptors` (segments.size() x 32, CV_8U);
  // each row is the one Describe gives for the whole list (a descriptor depends on its segment
  // and the image only).
  void DescribeRows(const cv::Mat& image_u8, const std::vector<LineSegment>& segments,
                    const std::vector<int>& rows, cv::Mat* descriptors);

  // The KeyLines handed to BinaryDescriptor (exposed for tests).
  std::vector<cv::line_descriptor::KeyLine> MakeKeyLines(const std::vector<LineSegment>& segments,
                                                         const cv::Size& image_size) const;

 private:
  LineDescriptorOptions options_;
  cv::Ptr<cv::line_descriptor::BinaryDescriptor> lbd_;
};

// Hamming distance of two 32-byte descriptor rows.
int HammingDistance32(const uint8_t* a, const uint8_t* b);

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LBD_DESCRIBER_H_
