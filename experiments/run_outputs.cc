#include "experiments/run_outputs.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "backend/depth_map_io.h"

namespace pldvo {
namespace {

std::string Numbered(const char* format, int a, int b = 0, int c = 0) {
  char buffer[128];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c);
  return buffer;
}

void DrawPixels(const std::vector<Eigen::Vector2d>& pixels, const cv::Vec3b& color,
                cv::Mat* canvas) {
  for (const Eigen::Vector2d& p : pixels) {
    const int x = static_cast<int>(std::lround(p.x()));
    const int y = static_cast<int>(std::lround(p.y()));
    if (x >= 0 && y >= 0 && x < canvas->cols && y < canvas->rows) {
      canvas->at<cv::Vec3b>(y, x) = color;
    }
  }
}

}  // namespace

RunOutputs::RunOutputs(const std::string& out_dir, const OutputOptions& options)
    : out_dir_(out_dir), options_(options) {}

void RunOutputs::ReportError(const std::string& what) {
  if (error_reported_) return;
  std::cerr << "pldvo run: output: " << what << " (further output errors not reported)\n";
  error_reported_ = true;
}

bool RunOutputs::WantsTrackingIterations(int frame_index) const {
  return options_.iteration_images_every > 0 && frame_index % options_.iteration_images_every == 0;
}

void RunOutputs::OnTrackingIteration(int frame_index, const cv::Mat& image,
                                     const TrackingIteration& iteration) {
  if (iteration.iteration == 0 || frame_index != initial_frame_ ||
      iteration.level != initial_level_) {
    initial_frame_ = frame_index;
    initial_level_ = iteration.level;
    initial_pixels_ = iteration.edge_pixels_in_cur;
  }
  try {
    const std::string dir = out_dir_ + "/iterations";
    std::filesystem::create_directories(dir);
    cv::Mat gray, canvas;
    image.convertTo(gray, CV_8U);
    cv::cvtColor(gray, canvas, cv::COLOR_GRAY2BGR);
    DrawPixels(initial_pixels_, cv::Vec3b(0, 0, 255), &canvas);
    DrawPixels(iteration.edge_pixels_in_cur, cv::Vec3b(0, 255, 0), &canvas);
    const std::string label = Numbered("frame %d  level %d  iteration %d", frame_index,
                                       iteration.level, iteration.iteration) +
                              "  cost " + std::to_string(iteration.cost);
    cv::putText(canvas, label, cv::Point(5, 15), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                cv::Scalar(255, 255, 0), 1);
    const std::string path = dir + Numbered("/frame_%06d_l%d_i%02d.png", frame_index,
                                            iteration.level, iteration.iteration);
    if (!cv::imwrite(path, canvas)) throw std::runtime_error("cannot write " + path);
    ++images_written_;
  } catch (const std::exception& e) {
    ReportError(e.what());
  }
}

bool RunOutputs::WantsKeyframeMaps() const {
  return options_.keyframe_depth_png || options_.keyframe_ply;
}

void RunOutputs::OnKeyframeFinished(const KeyframeInfo& keyframe, const SemiDenseDepthMap& map) {
  try {
    const std::string dir = out_dir_ + "/keyframes";
    std::filesystem::create_directories(dir);
    const std::string stem = dir + Numbered("/kf_%04d", keyframe.keyframe_id);
    if (options_.keyframe_depth_png) WriteInverseDepthPng(map, stem + "_idepth.png");
    if (options_.keyframe_ply) {
      WritePointCloudPly(map, keyframe.image, keyframe.camera, keyframe.world_from_kf,
                         stem + ".ply");
    }
    ++keyframes_written_;
  } catch (const std::exception& e) {
    ReportError(e.what());
  }
}

}  // namespace pldvo
