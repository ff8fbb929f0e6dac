#include "backend/edge_ba/edge_ba_line_triangulation.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace pldvo {

bool BackProjectedPlane(const PinholeCamera& camera, const SE3& cam_from_world,
                        const std::vector<Eigen::Vector2d>& pixels, WorldPlane* plane) {
  if (pixels.size() < 2) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : pixels) mean += p;
  mean /= static_cast<double>(pixels.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : pixels) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  // Largest eigenvalue = spread along the line (squared px, summed).
  if (!(eigen.eigenvalues()(1) > 1e-12)) return false;
  const Eigen::Vector2d normal_2d = eigen.eigenvectors().col(0);  // across the line
  // Image line l = (a, b, c), l . (u, v, 1) = 0; plane normal in the camera n_c = K^T l.
  const Eigen::Vector3d line(normal_2d.x(), normal_2d.y(), -normal_2d.dot(mean));
  const Eigen::Vector3d normal_in_cam(camera.fx * line.x(), camera.fy * line.y(),
                                      camera.cx * line.x() + camera.cy * line.y() + line.z());
  // n_c . (R X + t) = 0  ->  (R^T n_c) . X + n_c . t = 0.
  const double norm = normal_in_cam.norm();
  plane->normal = cam_from_world.rotation().inverse() * (normal_in_cam / norm);
  plane->offset = normal_in_cam.dot(cam_from_world.translation()) / norm;
  return true;
}

double LargestPlaneAngle(const std::vector<WorldPlane>& planes) {
  double smallest_cos = 1.0;
  for (size_t i = 0; i < planes.size(); ++i) {
    for (size_t j = i + 1; j < planes.size(); ++j) {
      smallest_cos = std::min(smallest_cos, std::abs(planes[i].normal.dot(planes[j].normal)));
    }
  }
  return std::acos(std::clamp(smallest_cos, 0.0, 1.0));
}

bool IntersectPlanes(const std::vector<WorldPlane>& planes, Eigen::Vector3d* point_in_world,
                     Eigen::Vector3d* direction_in_world) {
  if (planes.size() < 2) return false;
  Eigen::MatrixXd stacked(planes.size(), 4);
  for (size_t i = 0; i < planes.size(); ++i) {
    stacked.row(i) << planes[i].normal.transpose(), planes[i].offset;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(stacked, Eigen::ComputeFullV);
  // Homogeneous points (X; w) of the line satisfy stacked * (X; w) = 0: the two right singular
  // vectors of the smallest singular values span them. Rank 2 is needed (two distinct planes).
  if (!(svd.singularValues()(1) > 1e-9 * svd.singularValues()(0))) return false;
  const Eigen::Vector4d a = svd.matrixV().col(2);
  const Eigen::Vector4d b = svd.matrixV().col(3);
  // The combination with w = 0 is the point at infinity (direction); the one with w = 1 a point.
  const Eigen::Vector3d direction = b(3) * a.head<3>() - a(3) * b.head<3>();
  const double w_sq = a(3) * a(3) + b(3) * b(3);
  if (!(direction.norm() > 1e-12) || !(w_sq > 1e-24)) return false;  // line at infinity
  *direction_in_world = direction.normalized();
  const Eigen::Vector3d point = (a(3) * a.head<3>() + b(3) * b.head<3>()) / w_sq;
  // The point of the line nearest the world origin.
  *point_in_world = point - *direction_in_world * direction_in_world->dot(point);
  return point_in_world->allFinite();
}

}  // namespace pldvo
