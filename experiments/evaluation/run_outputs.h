// The optional outputs of `pldvo run` (config section `output`), written by an OdometryObserver so
// that the odometry core stays free of file I/O:
//   OUT/iterations/frame_NNNNNN_lL_iII.png  tracking iterations of every N-th frame: the
//       keyframe's edge points reprojected with the iteration's pose (green) over the current
//       frame, the initial pose's reprojection of the level in red (the paper's Fig. 2);
//   OUT/keyframes/kf_KKKK_idepth.png        the keyframe's inverse-depth map (colour, JET);
//   OUT/keyframes/kf_KKKK.ply               its semi-dense points in the world frame;
//   OUT/keyframe_maps.csv                   each keyframe's map against the dataset's depth
//       image (scale-aligned median relative error, NEES; all pixels and `continuous` ones).
// Write failures are reported once to stderr and never stop the run.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_RUN_OUTPUTS_H_
#define PLDVO_EXPERIMENTS_EVALUATION_RUN_OUTPUTS_H_

#include <Eigen/Core>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "backend/odometry/odometry_config.h"
#include "backend/odometry/odometry_observer.h"
#include "backend/odometry/sequence_runner.h"
#include "core/dataset.h"
#include "experiments/evaluation/mapping_ground_truth.h"

namespace pldvo {

// A retired keyframe's map against the GT depth of its frame (output.keyframe_map_error). `scale`
// = median(d_gt / d) aligns the monocular map; `continuous` leaves out GT discontinuities.
struct KeyframeMapError {
  int keyframe_id = -1;
  int frame_index = -1;
  double timestamp = 0.0;
  double scale = 0.0;
  DepthErrorStats all;
  DepthErrorStats continuous;
};

class RunOutputs : public RunObserver {
 public:
  // `dataset` gives the depth images for keyframe_map_error (may be null when that is off).
  RunOutputs(const std::string& out_dir, const OutputOptions& options,
             const Dataset* dataset = nullptr);

  bool WantsTrackingIterations(int frame_index) const override;
  void OnTrackingIteration(int frame_index, const cv::Mat& image,
                           const TrackingIteration& iteration) override;
  bool WantsKeyframeMaps() const override;
  void OnKeyframeFinished(const KeyframeInfo& keyframe, const SemiDenseDepthMap& map) override;

  int images_written() const { return images_written_; }
  int keyframes_written() const { return keyframes_written_; }
  // summary.json's `keyframe_maps`: the keyframes evaluated and the median over them of each
  // statistic; null when none was.
  nlohmann::json KeyframeMapSummary() const;
  // With output.keyframe_map_error: summary.json's `keyframe_maps` and its line in the report.
  void AddToSummary(nlohmann::json* summary) const override;
  std::string ReportLine() const override;

 private:
  void ReportError(const std::string& what);
  void EvaluateKeyframeMap(const KeyframeInfo& keyframe, const SemiDenseDepthMap& map);

  std::string out_dir_;
  OutputOptions options_;
  // Edge pixels of the current level's first iteration (drawn in red on later iterations).
  int initial_frame_ = -1;
  int initial_level_ = -1;
  std::vector<Eigen::Vector2d> initial_pixels_;
  int images_written_ = 0;
  int keyframes_written_ = 0;
  bool error_reported_ = false;
  const Dataset* dataset_ = nullptr;
  std::ofstream map_error_file_;
  std::vector<KeyframeMapError> map_errors_;
};

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_RUN_OUTPUTS_H_
