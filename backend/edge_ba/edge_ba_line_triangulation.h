// Initial 3D lines for edge bundle adjustment from their 2D observations (docs/edge_ba.md):
// each observation back-projects to a plane through its camera centre; the line is the
// intersection of the planes in the least-squares sense: the homogeneous points (X; 1) of the
// line span the two-dimensional (right) null space of the stacked plane vectors (n_i; delta_i)
// (Hartley & Zisserman, "Multiple View Geometry", 2nd ed., Sec. 12.8, the line from planes).
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_LINE_TRIANGULATION_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_LINE_TRIANGULATION_H_

#include <Eigen/Core>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// A plane normal . X + offset = 0 in the world, |normal| = 1.
struct WorldPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
};

// The plane through the camera centre and the image line fitted (total least squares) to
// `pixels`. Returns false when fewer than two distinct pixels are given (spread < 1e-6 px).
bool BackProjectedPlane(const PinholeCamera& camera, const SE3& cam_from_world,
                        const std::vector<Eigen::Vector2d>& pixels, WorldPlane* plane);

// The largest angle (radians, in [0, pi/2]) between the normals of any two planes: how well the
// planes pin down the line they share.
double LargestPlaneAngle(const std::vector<WorldPlane>& planes);

// The line common to >= 2 planes (least squares): a point on it (the one nearest the origin of
// the world) and its unit direction. Returns false for fewer than two planes or when the planes
// are (numerically) one plane.
bool IntersectPlanes(const std::vector<WorldPlane>& planes, Eigen::Vector3d* point_in_world,
                     Eigen::Vector3d* direction_in_world);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_LINE_TRIANGULATION_H_
