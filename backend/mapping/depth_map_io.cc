#include "backend/mapping/depth_map_io.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "core/statistics.h"

namespace pldvo {

cv::Mat ColorizeInverseDepth(const SemiDenseDepthMap& map, double idepth_min, double idepth_max) {
  if (!(idepth_max > idepth_min)) {
    std::vector<float> values;
    for (int i = 0; i < map.num_pixels(); ++i) {
      if (map.valid(i)) values.push_back(map.idepth(i));
    }
    if (values.empty()) {
      idepth_min = 0.0;
      idepth_max = 1.0;
    } else {
      std::sort(values.begin(), values.end());
      idepth_min = values[static_cast<size_t>(0.02 * (values.size() - 1))];
      idepth_max = values[static_cast<size_t>(0.98 * (values.size() - 1))];
      if (!(idepth_max > idepth_min)) idepth_max = idepth_min + 1e-3;
    }
  }
  cv::Mat gray(map.height(), map.width(), CV_8U, cv::Scalar(0));
  cv::Mat mask(map.height(), map.width(), CV_8U, cv::Scalar(0));
  const double scale = 255.0 / (idepth_max - idepth_min);
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const int i = map.Index(x, y);
      if (!map.valid(i)) continue;
      gray.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>((map.idepth(i) - idepth_min) * scale);
      mask.at<uint8_t>(y, x) = 255;
    }
  }
  cv::Mat colour;
  cv::applyColorMap(gray, colour, cv::COLORMAP_JET);
  cv::Mat result(map.height(), map.width(), CV_8UC3, cv::Scalar(0, 0, 0));
  colour.copyTo(result, mask);
  return result;
}

void WriteInverseDepthPng(const SemiDenseDepthMap& map, const std::string& path, double idepth_min,
                          double idepth_max) {
  const cv::Mat image = ColorizeInverseDepth(map, idepth_min, idepth_max);
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw std::runtime_error("WriteInverseDepthPng: cannot write " + path);
}

int WritePointCloudPly(const SemiDenseDepthMap& map, const cv::Mat& image,
                       const PinholeCamera& camera, const SE3& world_from_cam,
                       const std::string& path) {
  if (image.cols != map.width() || image.rows != map.height() || image.channels() != 1) {
    throw std::invalid_argument("WritePointCloudPly: image must be gray of the map's size");
  }
  cv::Mat intensity;
  image.convertTo(intensity, CV_32F);
  int count = 0;
  for (int i = 0; i < map.num_pixels(); ++i) count += map.observed(i);
  std::ofstream out(path);
  if (!out) throw std::runtime_error("WritePointCloudPly: cannot open " + path);
  out << "ply\nformat ascii 1.0\ncomment pldvo semi-dense keyframe map (world frame, metres)\n"
      << "element vertex " << count << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property float intensity\nend_header\n";
  char line[128];
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const int i = map.Index(x, y);
      if (!map.observed(i)) continue;
      const Eigen::Vector3d point_in_cam = camera.Unproject(Eigen::Vector2d(x, y)) / map.idepth(i);
      const Eigen::Vector3d point_in_world = world_from_cam * point_in_cam;
      std::snprintf(line, sizeof(line), "%.6g %.6g %.6g %.1f\n", point_in_world.x(),
                    point_in_world.y(), point_in_world.z(), intensity.at<float>(y, x));
      out << line;
    }
  }
  if (!out) throw std::runtime_error("WritePointCloudPly: write failed for " + path);
  return count;
}

cv::Mat NormalizedObservedDepth(const SemiDenseDepthMap& map, int* count, double* median_idepth) {
  std::vector<double> idepths;
  for (int i = 0; i < map.num_pixels(); ++i) {
    if (map.observed(i) && map.idepth(i) > 0.0) idepths.push_back(map.idepth(i));
  }
  *count = static_cast<int>(idepths.size());
  if (idepths.empty()) return cv::Mat();
  const double median = Median(idepths);
  if (median_idepth != nullptr) *median_idepth = median;
  cv::Mat depth = cv::Mat::zeros(map.height(), map.width(), CV_32F);
  for (int i = 0; i < map.num_pixels(); ++i) {
    if (!map.observed(i) || map.idepth(i) <= 0.0) continue;
    depth.at<float>(i / map.width(), i % map.width()) = static_cast<float>(median / map.idepth(i));
  }
  return depth;
}

}  // namespace pldvo
