// A dataset frame as loaded for the odometry: the frame or why it could not be loaded, and with a
// FramePreparer its per-image work done on the loading thread (odometry.frontend_thread).
#ifndef PLDVO_BACKEND_ODOMETRY_LOADED_FRAME_H_
#define PLDVO_BACKEND_ODOMETRY_LOADED_FRAME_H_

#include <optional>
#include <string>

#include "backend/odometry/frame_preparer.h"
#include "backend/odometry/odometry.h"
#include "core/dataset.h"

namespace pldvo {

struct LoadedFrame {
  Frame frame;
  std::string error;  // non-empty when loading failed
  double load_ms = 0.0;
  // odometry.frontend_thread: the frame's per-image work, done on the loading thread.
  std::optional<PreparedFrame> prepared;
};

// Loads frame `index` and, with a `preparer`, prepares it on the same (loading) thread. A frame
// that is not a gray image of the camera's size is left unprepared: ProcessFrame reports it.
LoadedFrame LoadFrame(const Dataset& dataset, int index, FramePreparer* preparer = nullptr);

// `loaded` (frame `index` of `dataset`) through `odometry`, quietly (the starts' own runs): a frame
// that failed to load or throws inside is skipped, as in the run (sequence_runner.cc). `depth` as
// Odometry::ProcessFrame's.
OdometryFrameResult ProcessOrSkip(const Dataset& dataset, int index, const LoadedFrame& loaded,
                                  Odometry* odometry, const cv::Mat& depth = cv::Mat());

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_LOADED_FRAME_H_
