// Edge BA lines -> keyframe inverse depths (docs/edge_ba.md, "Line depths in the depth map").
//
// A 3D line L = [o, d] (ceres::LineManifold<3>: o any point of the line, |d| = 1) in the
// keyframe's camera frame, with the 4x4 covariance Sigma of its tangent perturbation delta
// (L(delta) = LineManifold<3>::Plus(L, delta)), and the ray of pixel x, r = K^-1 (x; 1). As r_z
// = 1, the ray point s r has depth s and inverse depth 1/s. Closest approach of s r and o + t d
// (the normal equations of min |s r - o - t d|^2):
//   a = r.r, b = r.d, c = d.d, e = r.o, f = d.o, den = a c - b^2,
//   s = (c e - b f) / den,   t = (b e - a f) / den,   idepth = 1 / s.
// Skipped (false) when the ray and the line are near-parallel (den / (a c) = sin^2(angle) <
// kMinSinAngle^2), the point is behind the camera (s <= 0), or the ray misses the line by more
// than max_miss_ratio * s (|s r - o - t d| / s is the miss as an angle seen from the centre).
// Variance of the inverse depth from the line's uncertainty (first order):
//   J = d idepth(L(delta)) / d delta at delta = 0 (1x4, central differences through Plus),
//   var = J Sigma J^T.
// A world line with tangent covariance Sigma_w moves into a camera frame by cam_from_world; its
// tangent covariance there is G Sigma_w G^T with
//   G = d Minus(cam_from_world L_w(delta), cam_from_world L_w) / d delta at 0 (4x4, numeric),
// since the manifold's tangent basis depends on the direction and does not rotate with it.
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_LINE_DEPTH_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_LINE_DEPTH_H_

#include <Eigen/Core>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// Rays closer than this (sine of the angle) to the line's direction are near-parallel.
constexpr double kMinSinAngle = 0.02;

// An optimised 3D line of the edge BA as the mapping thread uses it: the keyframe edge (the id in
// the keyframe's EdgeTrace and depth map) it was observed as, the line in the keyframe's camera
// frame and its tangent covariance there.
struct KeyframeLine {
  int edge_id = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();               // o (keyframe frame)
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();          // d, unit
  Eigen::Matrix4d tangent_covariance = Eigen::Matrix4d::Zero();  // Sigma
};

// The line [point, direction] in the frame cam_from_world, its tangent covariance propagated by
// G (see above). direction need not be unit (normalised first).
KeyframeLine LineInCamera(const SE3& cam_from_world, const Eigen::Vector3d& point_in_world,
                          const Eigen::Vector3d& direction_in_world,
                          const Eigen::Matrix4d& tangent_covariance_in_world, int edge_id);

// The inverse depth of the ray of `pixel` at its closest approach to the line (see above); false
// when skipped.
bool RayLineInverseDepth(const PinholeCamera& camera, const Eigen::Vector2d& pixel,
                         const Eigen::Vector3d& point, const Eigen::Vector3d& direction,
                         double max_miss_ratio, double* idepth);

// ... and its variance J Sigma J^T. False when skipped at the line or any differentiation step.
bool RayLineInverseDepthAndVariance(const PinholeCamera& camera, const Eigen::Vector2d& pixel,
                                    const KeyframeLine& line, double max_miss_ratio, double* idepth,
                                    double* idepth_var);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_LINE_DEPTH_H_
