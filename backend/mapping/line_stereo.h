// Line-guided stereo (Yang & Scherer, ICRA 2017, Sec. V-A): a keyframe pixel x on an edge whose
// line l1 (keyframe) is matched to the line l2 in the current frame is matched at the
// intersection of x's epipolar line with l2, with no photometric search. Equivalently the ray of
// x meets the 3D line triangulated from the two back-projected planes, written in keyframe
// coordinates as the rows of (eq. 8)
//   L = [ l1^T K        0         ]
//       [ l2^T K R   l2^T K t     ],   (R, t) = cur_from_ref,
// whose 2-D null space is the 3D line. For x on l1 the ray lies in the first plane, so its
// inverse depth follows from the second (eq. 9):
//   l2^T K (R K^-1 (x; 1) / d + t) = 0   =>   d = - l2^T K R K^-1 (x; 1) / (l2^T K t).
// The disparity along the epipolar line has the variance (eq. 10)
//   sigma_lambda^2 = sigma_l^2 / sin^2(theta) + sigma_g^2 cot^2(theta),
// theta the angle between the epipolar line and the edge, sigma_g the epipolar line's (pose)
// position error, sigma_l the edges' perpendicular position error: that of the current edge at the
// match, x'^T Sigma_l2 x', plus that of the keyframe edge at x, x^T Sigma_l1 x (a keyframe edge off
// by delta moves the foot point of x, and so its epipolar line, by delta across the edge, to first
// order in the small motion); converted to inverse depth by alpha = 1 / |d tau / d d| as in the
// photometric case. The keyframe edge's part is the same error in every frame: it is returned as
// the observation's shared variance.
#ifndef PLDVO_BACKEND_MAPPING_LINE_STEREO_H_
#define PLDVO_BACKEND_MAPPING_LINE_STEREO_H_

#include <Eigen/Core>

#include "backend/mapping/epipolar_stereo.h"
#include "backend/mapping/mapping_options.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"
#include "residuals/covariance_models.h"

namespace pldvo {

// Eq. 8: the planes (n^T, offset) back-projected from the keyframe line l1 and the current line
// l2, both in keyframe coordinates: plane . (X; 1) = 0.
Eigen::Matrix<double, 2, 4> BackProjectedPlanes(const Eigen::Vector3d& line_in_ref,
                                                const Eigen::Vector3d& line_in_cur,
                                                const PinholeCamera& camera,
                                                const SE3& cur_from_ref);

// A 3D line X = point + s direction (|direction| = 1); point is the line's closest point to the
// keyframe centre.
struct Line3d {
  Eigen::Vector3d point_in_ref = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

// The null space of the 2x4 plane matrix: direction n1 x n2, point the minimum-norm solution.
// False when the planes are (nearly) parallel (|sin| of their angle below 1e-9), e.g. for a line
// in the epipolar plane.
bool TriangulateLine(const Eigen::Matrix<double, 2, 4>& planes, Line3d* line);

// Eq. 9: inverse depth of the ray of x at its intersection with the plane of l2. False when the
// plane contains the ray direction (l2^T K t ~ 0: no baseline across the edge).
bool IdepthFromLinePlane(const EpipolarGeometry& geometry, const Eigen::Vector2d& pixel_in_ref,
                         const Eigen::Vector3d& line_in_cur, double* idepth);

// Eq. 10: the disparity variance (pixels^2) for the edge position variance line_position_var,
// the epipolar position variance epipolar_position_var (both pixels^2), angle theta (radians).
double LineDisparityVar(double line_position_var, double epipolar_position_var, double theta);

// Line-guided stereo of x against the matched current line. The observation must fall in
// [idepth_min, idepth_max] (the prior interval, otherwise kLineOutOfRange) and theta must be at
// least options.min_line_epipolar_angle_deg (otherwise kLineIllConditioned: the caller falls back
// to the SSD search). When `current` and `patch` are given and options.line_stereo_check_ssd, the
// match must also pass the photometric check (5-sample SSD RMS <= max_ssd_rms, else
// kLargeError).
//
// `pixel_on_line` is the point of l1 whose ray meets the 3D line (the foot point of a traced
// pixel on l1); the observation's inverse depth is that of the 3D line there, and its current
// pixel and SSD check are those of `pixel_in_ref` at that inverse depth. `ref_line_position_var`
// is l1's perpendicular position variance there (pixels^2; 0 for an exact keyframe edge).
StereoStatus LineGuidedStereo(const EpipolarGeometry& geometry, const Eigen::Vector2d& pixel_in_ref,
                              const Eigen::Vector2d& pixel_on_line, double ref_line_position_var,
                              const LineWithCovariance& line_in_cur, double idepth_min,
                              double idepth_max, const MappingOptions& options,
                              const ImagePyramid* current, const EpipolarPatch* patch,
                              StereoObservation* observation);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_LINE_STEREO_H_
