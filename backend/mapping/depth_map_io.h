// Output of a keyframe's semi-dense map (no GUI): the inverse-depth map as a colour PNG and the
// semi-dense points as an ASCII PLY point cloud.
#ifndef PLDVO_BACKEND_MAPPING_DEPTH_MAP_IO_H_
#define PLDVO_BACKEND_MAPPING_DEPTH_MAP_IO_H_

#include <opencv2/core.hpp>
#include <string>

#include "backend/mapping/semi_dense_depth_map.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// The inverse-depth map as a BGR image: valid pixels coloured by cv::COLORMAP_JET over
// [idepth_min, idepth_max] (red near, blue far), invalid pixels black. With idepth_min >=
// idepth_max the range is the 2nd..98th percentile of the valid inverse depths.
cv::Mat ColorizeInverseDepth(const SemiDenseDepthMap& map, double idepth_min = 0.0,
                             double idepth_max = 0.0);
// Writes ColorizeInverseDepth to a PNG; throws std::runtime_error naming the path on failure.
void WriteInverseDepthPng(const SemiDenseDepthMap& map, const std::string& path,
                          double idepth_min = 0.0, double idepth_max = 0.0);

// Writes the valid hypotheses with idepth > 0 and at least one stereo observation (initial and
// hole-filled guesses are left out) as an ASCII PLY ("x y z intensity" per vertex):
// the point K^-1 (x; 1) / idepth mapped by world_from_cam, the intensity of `image` (8-bit or
// float gray of the map's size) at the pixel. Returns the number of points written; throws
// std::runtime_error naming the path when the file cannot be written and
// std::invalid_argument on a size mismatch.
int WritePointCloudPly(const SemiDenseDepthMap& map, const cv::Mat& image,
                       const PinholeCamera& camera, const SE3& world_from_cam,
                       const std::string& path);

// The z-depth image (CV_32F, the map's size) of the hypotheses with at least one stereo
// observation and idepth > 0, scaled so that their median inverse depth is 1 (the scale of a
// monocular map is arbitrary), 0 elsewhere: a start map for odometry.init_depth_idepth_var-style
// initialisation. Sets *count to the number of such hypotheses and, if given, *median_idepth to
// their median inverse depth; empty image when there are none.
cv::Mat NormalizedObservedDepth(const SemiDenseDepthMap& map, int* count,
                                double* median_idepth = nullptr);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_DEPTH_MAP_IO_H_
