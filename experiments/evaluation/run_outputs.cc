#include "experiments/evaluation/run_outputs.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "backend/mapping/depth_map_io.h"
#include "core/evaluation.h"

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

constexpr const char* kStatColumns[] = {"count",         "median_rel_error", "mean_nees",
                                        "median_nees",   "within_2sigma",    "gross_fraction",
                                        "bulk_mean_nees"};

std::vector<double> StatValues(const DepthErrorStats& s) {
  return {static_cast<double>(s.count),
          s.median_rel_error,
          s.mean_nees,
          s.median_nees,
          s.within_2sigma,
          s.gross_fraction,
          s.bulk_mean_nees};
}

}  // namespace

RunOutputs::RunOutputs(const std::string& out_dir, const OutputOptions& options,
                       const Dataset* dataset)
    : out_dir_(out_dir), options_(options), dataset_(dataset) {}

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
  return options_.keyframe_depth_png || options_.keyframe_ply || options_.keyframe_map_error;
}

void RunOutputs::OnKeyframeFinished(const KeyframeInfo& keyframe, const SemiDenseDepthMap& map) {
  try {
    if (options_.keyframe_depth_png || options_.keyframe_ply) {
      const std::string dir = out_dir_ + "/keyframes";
      std::filesystem::create_directories(dir);
      const std::string stem = dir + Numbered("/kf_%04d", keyframe.keyframe_id);
      if (options_.keyframe_depth_png) WriteInverseDepthPng(map, stem + "_idepth.png");
      if (options_.keyframe_ply) {
        WritePointCloudPly(map, keyframe.image, keyframe.camera, keyframe.world_from_kf,
                           stem + ".ply");
      }
      ++keyframes_written_;
    }
    if (options_.keyframe_map_error) EvaluateKeyframeMap(keyframe, map);
  } catch (const std::exception& e) {
    ReportError(e.what());
  }
}

void RunOutputs::EvaluateKeyframeMap(const KeyframeInfo& keyframe, const SemiDenseDepthMap& map) {
  const cv::Mat depth = dataset_ != nullptr ? dataset_->LoadDepth(keyframe.frame_index) : cv::Mat();
  if (depth.empty()) {
    ReportError("output.keyframe_map_error: no depth image for frame " +
                std::to_string(keyframe.frame_index));
    return;
  }
  const cv::Mat gt_idepth = InverseDepthFromDepth(depth);
  KeyframeMapError error;
  error.keyframe_id = keyframe.keyframe_id;
  error.frame_index = keyframe.frame_index;
  error.timestamp = keyframe.timestamp;
  error.scale = MedianInverseDepthRatio(map, gt_idepth);
  if (!(error.scale > 0.0)) return;  // no observed hypothesis with depth: nothing to compare
  error.all = EvaluateDepthMap(map, gt_idepth, cv::Mat(), true, error.scale);
  const cv::Mat continuous = ContinuousDepthMask(gt_idepth, options_.discontinuity_radius_px,
                                                 options_.discontinuity_rel_step);
  error.continuous = EvaluateDepthMap(map, gt_idepth, continuous, true, error.scale);
  map_errors_.push_back(error);

  if (!map_error_file_.is_open()) {
    map_error_file_.open(out_dir_ + "/keyframe_maps.csv");
    map_error_file_ << "keyframe_id,frame_index,timestamp,scale";
    for (const char* prefix : {"", "continuous_"}) {
      for (const char* column : kStatColumns) map_error_file_ << "," << prefix << column;
    }
    map_error_file_ << "\n";
  }
  map_error_file_ << error.keyframe_id << "," << error.frame_index << "," << std::setprecision(17)
                  << error.timestamp << "," << std::setprecision(6) << error.scale;
  for (const DepthErrorStats* stats : {&error.all, &error.continuous}) {
    for (double value : StatValues(*stats)) map_error_file_ << "," << value;
  }
  map_error_file_ << std::endl;
  if (!map_error_file_) ReportError("cannot write " + out_dir_ + "/keyframe_maps.csv");
}

nlohmann::json RunOutputs::KeyframeMapSummary() const {
  if (map_errors_.empty()) return nullptr;
  nlohmann::json summary;
  summary["keyframes"] = map_errors_.size();
  std::vector<double> scales;
  for (const KeyframeMapError& e : map_errors_) scales.push_back(e.scale);
  summary["scale_median"] = Median(scales);
  for (const char* prefix : {"", "continuous_"}) {
    for (size_t k = 1; k < std::size(kStatColumns); ++k) {
      std::vector<double> column;
      for (const KeyframeMapError& e : map_errors_) {
        column.push_back(StatValues(*prefix == '\0' ? e.all : e.continuous)[k]);
      }
      summary[std::string(prefix) + kStatColumns[k] + "_median"] = Median(column);
    }
  }
  return summary;
}

void RunOutputs::AddToSummary(nlohmann::json* summary) const {
  if (options_.keyframe_map_error) (*summary)["keyframe_maps"] = KeyframeMapSummary();
}

std::string RunOutputs::ReportLine() const {
  if (!options_.keyframe_map_error) return "";
  const nlohmann::json maps = KeyframeMapSummary();
  if (maps.is_null()) return "keyframe maps: none evaluated (no depth images?)";
  std::ostringstream line;
  line << std::setprecision(3) << "keyframe maps (" << maps["keyframes"].get<int>()
       << ", medians): rel. err " << maps["median_rel_error_median"].get<double>()
       << ", continuous: rel. err " << maps["continuous_median_rel_error_median"].get<double>()
       << ", mean NEES " << maps["continuous_mean_nees_median"].get<double>() << ", gross "
       << maps["continuous_gross_fraction_median"].get<double>();
  return line.str();
}

}  // namespace pldvo
