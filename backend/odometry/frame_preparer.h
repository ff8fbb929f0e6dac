// The per-image work of a frame, which depends on nothing but the image: the image pyramid and
// the line frontend's detection, merging and LBD description (steps 1 of odometry.h). Because it
// is a pure function of the image, a driver can prepare frame i + 1 on another thread while frame
// i is tracked (odometry.frontend_thread in `pldvo run`) without changing any result.
#ifndef PLDVO_BACKEND_ODOMETRY_FRAME_PREPARER_H_
#define PLDVO_BACKEND_ODOMETRY_FRAME_PREPARER_H_

#include <memory>
#include <opencv2/core.hpp>

#include "backend/odometry/odometry_config.h"
#include "core/image_pyramid.h"
#include "frontend/line_frontend.h"

namespace pldvo {

struct PreparedFrame {
  cv::Mat image;  // the input image (shared, not copied)
  ImagePyramid pyramid;
  LineFrame lines;  // no segments when odometry.use_lines is false
  double pyramid_ms = 0.0;
};

class FramePreparer {
 public:
  // Throws std::invalid_argument when the line frontend options are invalid.
  explicit FramePreparer(const OdometryConfig& config);

  // Not thread-safe (LineFrontend::Process): one preparer per thread at a time.
  PreparedFrame Prepare(const cv::Mat& image);

 private:
  int num_levels_;
  std::unique_ptr<LineFrontend> frontend_;  // null without lines
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_ODOMETRY_FRAME_PREPARER_H_
