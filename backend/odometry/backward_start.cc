#include "backend/odometry/backward_start.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "backend/odometry/loaded_frame.h"
#include "core/frame_range_view.h"
#include "core/wall_clock.h"

namespace pldvo {

BackwardStart TrackBackwardFromAnchor(const Dataset& dataset, const OdometryConfig& run_config,
                                      int anchor, const cv::Mat& anchor_depth) {
  if (anchor < 1 || anchor >= dataset.size()) {
    throw std::invalid_argument("TrackBackwardFromAnchor: anchor " + std::to_string(anchor) +
                                " is not a later frame of the dataset's " +
                                std::to_string(dataset.size()));
  }
  const auto start = WallClock::now();
  const FrameRangeView backwards(dataset, anchor, FrameRangeView::Direction::kBackward);
  OdometryConfig config = run_config;
  config.odometry.parallel_mapping = false;
  config.odometry.compare_solver = OdometryOptions::CompareSolver::kNone;
  config.backend.edge_ba.enabled = false;
  config.backend.windowed_ba.enabled = false;
  Odometry odometry(dataset.camera(), config);
  BackwardStart result;
  for (int i = 0; i < backwards.size(); ++i) {
    const OdometryFrameResult frame = ProcessOrSkip(backwards, i, LoadFrame(backwards, i),
                                                    &odometry, i == 0 ? anchor_depth : cv::Mat());
    if (i > 0 && IsTracked(frame.status)) {
      result.poses.push_back({dataset.timestamp(backwards.DatasetIndex(i)), frame.world_from_cam});
    }
  }
  odometry.Finish();
  std::reverse(result.poses.begin(), result.poses.end());
  result.statistics = odometry.statistics();
  result.ms = MsSince(start);
  return result;
}

}  // namespace pldvo
