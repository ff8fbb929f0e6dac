// Propagation of a keyframe's inverse-depth map to a new keyframe (Engel, Sturm, Cremers,
// ICCV 2013, Sec. 2.4). Each valid hypothesis (x, d0, V0) of the old keyframe is moved with
// new_from_old = (R, t): P = R K^-1 (x; 1) / d0 + t, d1 = 1 / P_z, x' = pi(P) rounded to the
// nearest pixel. The variance is propagated to first order and inflated by the prediction
// noise sigma_p^2:
//   V1 = J^2 V0 + sigma_p^2,   J = d d1 / d d0 = (r3^T K^-1 (x; 1)) d1^2 / d0^2,
// which for a pure translation along the optical axis is Engel's (d1 / d0)^4 V0 + sigma_p^2.
// A hypothesis is dropped when x' leaves the image (border), is not a candidate of the new
// keyframe (low gradient, no edge), or the two keyframes' intensities at x and x' differ by more
// than max_propagation_intensity_diff (occlusion, wrong depth; the new keyframe's intensity taken
// to the old one's brightness, e^-a (I_new - b), with `new_from_old_brightness` = (a, b):
// residuals/affine_brightness.h). Collisions (two hypotheses on one
// new pixel): statistically compatible ones ((d_a - d_b)^2 <= g^2 (V_a + V_b), g =
// outlier_gate_sigmas) are fused as in the EKF; otherwise the nearer one (larger inverse depth)
// wins, as it occludes the other.
#ifndef PLDVO_BACKEND_MAPPING_DEPTH_PROPAGATION_H_
#define PLDVO_BACKEND_MAPPING_DEPTH_PROPAGATION_H_

#include <opencv2/core.hpp>

#include "backend/mapping/mapping_options.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/affine_brightness.h"

namespace pldvo {

struct PropagationStats {
  int propagated = 0;  // hypotheses of the new map
  int dropped_outside = 0;
  int dropped_not_candidate = 0;
  int dropped_intensity = 0;
  int collisions_fused = 0;
  int collisions_occluded = 0;
};

// The new keyframe's map: candidates selected from `new_keyframe` and `new_edge_id_map` (CV_32S
// or empty), holding the propagated hypotheses. Throws std::invalid_argument on size mismatch.
SemiDenseDepthMap PropagateDepthMap(const SemiDenseDepthMap& old_map,
                                    const ImagePyramid& old_keyframe,
                                    const ImagePyramid& new_keyframe,
                                    const cv::Mat& new_edge_id_map, const PinholeCamera& camera,
                                    const SE3& new_from_old, const MappingOptions& options,
                                    PropagationStats* stats,
                                    const AffineBrightness& new_from_old_brightness = {});

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_DEPTH_PROPAGATION_H_
