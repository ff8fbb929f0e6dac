#include "backend/odometry/loaded_frame.h"

#include <exception>

#include "core/wall_clock.h"

namespace pldvo {

LoadedFrame LoadFrame(const Dataset& dataset, int index, FramePreparer* preparer) {
  LoadedFrame loaded;
  const auto start = WallClock::now();
  try {
    loaded.frame = dataset.Load(index);
    if (loaded.frame.image.empty()) loaded.error = "empty image " + loaded.frame.path;
  } catch (const std::exception& e) {
    loaded.error = e.what();
  }
  loaded.load_ms = MsSince(start);
  const cv::Mat& image = loaded.frame.image;
  const PinholeCamera& camera = dataset.camera();
  if (preparer != nullptr && loaded.error.empty() && image.channels() == 1 &&
      image.cols == camera.width && image.rows == camera.height) {
    try {
      loaded.prepared = preparer->Prepare(image);
    } catch (const std::exception&) {
      // Left unprepared: ProcessFrame(image) repeats the work and reports the failure.
    }
  }
  return loaded;
}

OdometryFrameResult ProcessOrSkip(const Dataset& dataset, int index, const LoadedFrame& loaded,
                                  Odometry* odometry, const cv::Mat& depth) {
  if (!loaded.error.empty())
    return odometry->SkipFrame(index, dataset.timestamp(index), loaded.error);
  try {
    return odometry->ProcessFrame(index, loaded.frame.timestamp, loaded.frame.image, depth);
  } catch (const std::exception& e) {
    return odometry->SkipFrame(index, loaded.frame.timestamp, e.what());
  }
}

}  // namespace pldvo
