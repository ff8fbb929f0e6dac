#include "frontend/edge_tracer.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace pldvo {

EdgeTracer::EdgeTracer(const EdgeTracerOptions& options) : options_(options) {
  const std::string error = options_.Check();
  if (!error.empty()) throw std::invalid_argument("EdgeTracerOptions: " + error);
}

EdgeTrace EdgeTracer::Trace(const std::vector<LineSegment>& segments, const std::vector<int>& ids,
                            const cv::Size& image_size) const {
  if (image_size.width <= 0 || image_size.height <= 0) {
    throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                ": empty image size");
  }
  EdgeTrace trace;
  trace.id_map = cv::Mat(image_size, CV_32S, cv::Scalar(-1));
  cv::Mat owner_distance(image_size, CV_32F, cv::Scalar(std::numeric_limits<float>::max()));
  const int border = options_.border_px;
  const int x_max = image_size.width - 1 - border, y_max = image_size.height - 1 - border;

  trace.lines.resize(ids.size());
  std::vector<char> seen(segments.size(), 0);
  for (size_t k = 0; k < ids.size(); ++k) {
    const int id = ids[k];
    if (id < 0 || id >= static_cast<int>(segments.size())) {
      throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                  ": line id " + std::to_string(id) + " out of range");
    }
    if (seen[id]) {
      throw std::invalid_argument(std::string(__FILE__) + ":" + std::to_string(__LINE__) +
                                  ": line id " + std::to_string(id) + " given twice");
    }
    seen[id] = 1;
    const LineSegment& s = segments[id];
    TracedLine& traced = trace.lines[k];
    traced.id = id;
    traced.segment = s;
    const Eigen::Vector2d delta = s.end - s.start;
    const bool x_major = std::abs(delta.x()) >= std::abs(delta.y());
    const int major = x_major ? 0 : 1, minor = 1 - major;
    if (std::abs(delta[major]) < 1e-9) continue;  // shorter than a pixel
    const double slope = delta[minor] / delta[major];
    const double m0 = std::min(s.start[major], s.end[major]);
    const double m1 = std::max(s.start[major], s.end[major]);
    for (int m = static_cast<int>(std::ceil(m0)); m <= static_cast<int>(std::floor(m1)); ++m) {
      const double centre = s.start[minor] + slope * (m - s.start[major]);
      const int c = static_cast<int>(std::lround(centre));
      for (int o = -options_.half_width_px; o <= options_.half_width_px; ++o) {
        Eigen::Vector2i pixel;
        pixel[major] = m;
        pixel[minor] = c + o;
        if (pixel.x() < border || pixel.y() < border || pixel.x() > x_max || pixel.y() > y_max) {
          continue;
        }
        const float distance = static_cast<float>(std::abs(s.SignedDistance(pixel.cast<double>())));
        float& owner = owner_distance.at<float>(pixel.y(), pixel.x());
        int& map_id = trace.id_map.at<int>(pixel.y(), pixel.x());
        if (distance < owner || (distance == owner && id < map_id)) {
          owner = distance;
          map_id = id;
        }
        traced.pixels.push_back(pixel);
      }
    }
  }
  // Keep in each list only the pixels the line owns.
  for (TracedLine& traced : trace.lines) {
    size_t kept = 0;
    for (const Eigen::Vector2i& p : traced.pixels) {
      if (trace.id_map.at<int>(p.y(), p.x()) == traced.id) traced.pixels[kept++] = p;
    }
    traced.pixels.resize(kept);
  }
  return trace;
}

}  // namespace pldvo
