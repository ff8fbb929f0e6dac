#include "frontend/line_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pldvo {
namespace {

// Sum over samples along the segment of I(p + 1.5 n) - I(p - 1.5 n), n = (-d_y, d_x), on the
// octave image (nearest-pixel lookups, clamped to the image): positive when the brighter side
// is along n.
double PolaritySum(const cv::Mat& image, const Eigen::Vector2d& start, const Eigen::Vector2d& end) {
  const Eigen::Vector2d delta = end - start;
  const double length = delta.norm();
  const Eigen::Vector2d n = Eigen::Vector2d(-delta.y(), delta.x()) / length;
  const int num_samples = std::clamp(static_cast<int>(length / 2.0), 3, 32);
  auto pixel = [&image](const Eigen::Vector2d& p) {
    const int x = std::clamp(static_cast<int>(std::lround(p.x())), 0, image.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(p.y())), 0, image.rows - 1);
    return static_cast<double>(image.at<uint8_t>(y, x));
  };
  double sum = 0.0;
  for (int i = 0; i < num_samples; ++i) {
    const double t = (i + 0.5) / num_samples;
    const Eigen::Vector2d p = start + t * delta;
    sum += pixel(p + 1.5 * n) - pixel(p - 1.5 * n);
  }
  return sum;
}

}  // namespace

cv::Mat ToGray8(const cv::Mat& image) {
  if (image.empty() || image.channels() != 1) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": expected a non-empty single-channel image");
  }
  if (image.type() == CV_8U) return image;
  if (image.type() != CV_32F) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": expected a CV_8U or CV_32F image");
  }
  cv::Mat gray;
  image.convertTo(gray, CV_8U);  // rounds and saturates to 0..255
  return gray;
}

std::vector<cv::Mat> BuildOctaves(const cv::Mat& image_u8, int num_octaves) {
  std::vector<cv::Mat> octaves(std::max(1, num_octaves));
  octaves[0] = image_u8;
  for (size_t k = 1; k < octaves.size(); ++k) {
    const cv::Mat& prev = octaves[k - 1];
    cv::pyrDown(prev, octaves[k], cv::Size(prev.cols / 2, prev.rows / 2));
  }
  return octaves;
}

LineDetector::LineDetector(const LineDetectorOptions& options) : options_(options) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument("LineDetectorOptions: " + error);
  switch (options_.method) {
    case LineDetectorOptions::Method::kLsd:
      lsd_ =
          cv::createLineSegmentDetector(cv::LSD_REFINE_NONE, options_.lsd_scale, 0.6,
                                        options_.lsd_quant, options_.lsd_angle_tolerance_deg,
                                        options_.lsd_log_eps, options_.lsd_density_threshold, 1024);
      break;
    case LineDetectorOptions::Method::kEdLines: {
      edlines_ = cv::ximgproc::createEdgeDrawing();
      cv::ximgproc::EdgeDrawing::Params params;
      params.GradientThresholdValue = options_.edlines_gradient_threshold;
      params.MinLineLength = options_.edlines_min_line_length;
      params.LineFitErrorThreshold = options_.edlines_line_fit_error;
      params.NFAValidation = options_.edlines_nfa_validation;
      edlines_->setParams(params);
      break;
    }
    case LineDetectorOptions::Method::kFld:
      fld_ = cv::ximgproc::createFastLineDetector(
          options_.fld_length_threshold, static_cast<float>(options_.fld_distance_threshold),
          options_.fld_canny_low, options_.fld_canny_high, 3, /*do_merge=*/false);
      break;
  }
}

void LineDetector::DetectOctave(const cv::Mat& image, std::vector<cv::Vec4f>* raw) {
  raw->clear();
  if (lsd_) {
    lsd_->detect(image, *raw);
  } else if (edlines_) {
    edlines_->detectEdges(image);
    edlines_->detectLines(*raw);
  } else {
    fld_->detect(image, *raw);
  }
}

std::vector<LineSegment> LineDetector::Detect(const std::vector<cv::Mat>& octaves) {
  const int last_octave = options_.first_octave + options_.num_octaves - 1;
  if (static_cast<int>(octaves.size()) <= last_octave) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": the pyramid has " + std::to_string(octaves.size()) +
                                " octaves, detection needs " + std::to_string(last_octave + 1));
  }
  std::vector<LineSegment> segments;
  std::vector<cv::Vec4f> raw;
  for (int octave = options_.first_octave; octave <= last_octave; ++octave) {
    const cv::Mat& image = octaves[octave];
    DetectOctave(image, &raw);
    const double scale = std::ldexp(1.0, octave);
    const double sigma_px = options_.endpoint_sigma_px * scale;
    // OpenCV's LSD subsamples by s = lsd_scale and returns x_s / s, but with pixel centres at
    // integers the original coordinate is (x_s + 0.5) / s - 0.5: add the difference (0.125 px
    // at s = 0.8; measured on a supersampled step edge, see tests/frontend).
    const double offset = lsd_ ? 0.5 / options_.lsd_scale - 0.5 : 0.0;
    for (const cv::Vec4f& r : raw) {
      Eigen::Vector2d start(r[0] + offset, r[1] + offset);
      Eigen::Vector2d end(r[2] + offset, r[3] + offset);
      if ((end - start).norm() * scale < std::max(options_.min_length_px, 1e-3)) continue;
      if (PolaritySum(image, start, end) < 0.0) std::swap(start, end);
      segments.push_back(MakeLineSegment(scale * start, scale * end, octave, sigma_px));
    }
  }
  return segments;
}

}  // namespace pldvo
