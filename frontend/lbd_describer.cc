#include "frontend/lbd_describer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace pldvo {

LbdDescriber::LbdDescriber(const LineDescriptorOptions& options) : options_(options) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument("LineDescriptorOptions: " + error);
  cv::line_descriptor::BinaryDescriptor::Params params;
  params.widthOfBand_ = options_.band_width;
  lbd_ = cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor(params);
}

std::vector<cv::line_descriptor::KeyLine> LbdDescriber::MakeKeyLines(
    const std::vector<LineSegment>& segments, const cv::Size& image_size) const {
  std::vector<cv::line_descriptor::KeyLine> keylines(segments.size());
  for (size_t i = 0; i < segments.size(); ++i) {
    const LineSegment& s = segments[i];
    const int octave = std::max(s.octave, options_.min_octave);
    const float inv_scale = static_cast<float>(std::ldexp(1.0, -octave));
    cv::line_descriptor::KeyLine& kl = keylines[i];
    kl.class_id = static_cast<int>(i);
    kl.octave = octave;
    kl.angle = static_cast<float>(s.angle);
    kl.startPointX = static_cast<float>(s.start.x());
    kl.startPointY = static_cast<float>(s.start.y());
    kl.endPointX = static_cast<float>(s.end.x());
    kl.endPointY = static_cast<float>(s.end.y());
    kl.sPointInOctaveX = kl.startPointX * inv_scale;
    kl.sPointInOctaveY = kl.startPointY * inv_scale;
    kl.ePointInOctaveX = kl.endPointX * inv_scale;
    kl.ePointInOctaveY = kl.endPointY * inv_scale;
    kl.lineLength = static_cast<float>(s.length) * inv_scale;
    // BinaryDescriptor samples numOfPixels steps of one octave pixel centred on the midpoint.
    kl.numOfPixels = std::max(2, static_cast<int>(std::lround(kl.lineLength)));
    if (options_.max_support_px > 0) {
      kl.numOfPixels = std::min(kl.numOfPixels, options_.max_support_px);
    }
    kl.pt =
        cv::Point2f(0.5f * (kl.startPointX + kl.endPointX), 0.5f * (kl.startPointY + kl.endPointY));
    kl.size = std::abs((kl.endPointX - kl.startPointX) * (kl.endPointY - kl.startPointY));
    kl.response = static_cast<float>(s.length) /
                  static_cast<float>(std::max(image_size.width, image_size.height));
  }
  return keylines;
}

cv::Mat LbdDescriber::Describe(const cv::Mat& image_u8, const std::vector<LineSegment>& segments) {
  if (image_u8.type() != CV_8U) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": LBD needs an 8-bit single-channel image");
  }
  if (segments.empty()) return cv::Mat(0, 32, CV_8U);
  std::vector<cv::line_descriptor::KeyLine> keylines = MakeKeyLines(segments, image_u8.size());
  cv::Mat descriptors;
  lbd_->compute(image_u8, keylines, descriptors);
  if (descriptors.rows != static_cast<int>(segments.size()) || descriptors.cols != 32 ||
      descriptors.type() != CV_8U) {
    throw std::runtime_error(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                             ": BinaryDescriptor returned an unexpected descriptor matrix");
  }
  return descriptors;
}

void LbdDescriber::DescribeRows(const cv::Mat& image_u8, const std::vector<LineSegment>& segments,
                                const std::vector<int>& rows, cv::Mat* descriptors) {
  if (descriptors->rows != static_cast<int>(segments.size()) || descriptors->cols != 32 ||
      descriptors->type() != CV_8U) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": descriptors must be a segments.size() x 32 CV_8U matrix");
  }
  std::vector<LineSegment> subset;
  subset.reserve(rows.size());
  for (int row : rows) subset.push_back(segments.at(row));
  const cv::Mat described = Describe(image_u8, subset);
  for (size_t k = 0; k < rows.size(); ++k) described.row(k).copyTo(descriptors->row(rows[k]));
}

int HammingDistance32(const uint8_t* a, const uint8_t* b) {
  int distance = 0;
  for (int k = 0; k < 4; ++k) {
    uint64_t wa, wb;
    std::memcpy(&wa, a + 8 * k, 8);
    std::memcpy(&wb, b + 8 * k, 8);
    distance += __builtin_popcountll(wa ^ wb);
  }
  return distance;
}

}  // namespace pldvo
