#include "backend/odometry/bootstrap_refiner.h"

#include <chrono>
#include <stdexcept>
#include <string>

#include "backend/mapping/depth_map_io.h"
#include "backend/odometry/odometry.h"
#include "backend/odometry/odometry_observer.h"
#include "core/wall_clock.h"

namespace pldvo {
namespace {

// Keeps the first keyframe's final map as z-depth (NormalizedObservedDepth).
class FirstKeyframeCapture : public OdometryObserver {
 public:
  bool WantsKeyframeMaps() const override { return true; }
  void OnKeyframeFinished(const KeyframeInfo& keyframe, const SemiDenseDepthMap& map) override {
    if (captured_ || keyframe.keyframe_id != 0) return;
    captured_ = true;
    depth_ = NormalizedObservedDepth(map, &points_);
  }
  bool captured() const { return captured_; }
  const cv::Mat& depth() const { return depth_; }
  int points() const { return points_; }

 private:
  bool captured_ = false;
  cv::Mat depth_;
  int points_ = 0;
};

}  // namespace

BootstrapRefinement RefineBootstrap(const Dataset& dataset, const OdometryConfig& config,
                                    int num_frames) {
  if (config.odometry.bootstrap_passes < 2) {
    throw std::invalid_argument("RefineBootstrap: odometry.bootstrap_passes must be >= 2");
  }
  const auto start = WallClock::now();
  OdometryConfig pass_config = config;
  pass_config.backend.edge_ba.enabled = false;
  pass_config.odometry.compare_solver = OdometryOptions::CompareSolver::kNone;
  pass_config.odometry.bootstrap_passes = 1;  // a pass is a plain run
  BootstrapRefinement refinement;
  for (int pass = 1; pass < config.odometry.bootstrap_passes; ++pass) {
    // Pass 1 starts from the random map, every later one from the previous pass's map.
    pass_config.odometry.init_depth_idepth_var =
        refinement.depth.empty() ? 0.0 : config.odometry.bootstrap_idepth_var;
    FirstKeyframeCapture capture;
    Odometry odometry(dataset.camera(), pass_config, &capture);
    int i = 0;  // after the loop: the frames processed
    for (; i < num_frames && !capture.captured(); ++i) {
      try {
        const Frame frame = dataset.Load(i);
        odometry.ProcessFrame(i, frame.timestamp, frame.image,
                              i == 0 ? refinement.depth : cv::Mat());
      } catch (const std::exception& e) {
        odometry.SkipFrame(i, dataset.timestamp(i), e.what());
      }
    }
    odometry.Finish();  // the first keyframe's map when the frames ended before a second one
    if (!capture.captured() || capture.points() == 0) {
      throw std::runtime_error("bootstrap refinement pass " + std::to_string(pass) +
                               ": the first keyframe's map has no observed hypothesis");
    }
    refinement.depth = capture.depth();
    refinement.frames.push_back(i);
    refinement.points.push_back(capture.points());
  }
  refinement.ms = MsSince(start);
  return refinement;
}

}  // namespace pldvo
