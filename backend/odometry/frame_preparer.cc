#include "backend/odometry/frame_preparer.h"

#include "core/wall_clock.h"

namespace pldvo {

FramePreparer::FramePreparer(const OdometryConfig& config)
    : num_levels_(config.odometry.num_levels) {
  if (config.odometry.use_lines) frontend_ = std::make_unique<LineFrontend>(config.lines);
}

PreparedFrame FramePreparer::Prepare(const cv::Mat& image) {
  const auto start = WallClock::now();
  PreparedFrame frame;
  frame.image = image;
  frame.pyramid = ImagePyramid(image, num_levels_);
  frame.pyramid_ms = MsSince(start);
  if (frontend_ != nullptr) frame.lines = frontend_->Process(image);
  return frame;
}

}  // namespace pldvo
