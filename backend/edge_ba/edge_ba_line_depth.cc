#include "backend/edge_ba/edge_ba_line_depth.h"

#include <ceres/line_manifold.h>

#include <array>
#include <cmath>

namespace pldvo {
namespace {

// Central-difference step in the tangent space (metres for the origin, radians for the
// direction): the lines are metres away, so truncation (h^2) and rounding (eps / h) errors are
// both ~1e-10 relative.
constexpr double kTangentStep = 1e-5;

// The miss test is not applied to the perturbed lines: only the intersection's sensitivity is
// wanted.
constexpr double kAnyMiss = 1e300;

using Line = std::array<double, 6>;

Line MakeLine(const Eigen::Vector3d& point, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = direction.normalized();
  return {point.x(), point.y(), point.z(), d.x(), d.y(), d.z()};
}

Line Perturbed(const Line& line, int k, double step) {
  Eigen::Vector4d delta = Eigen::Vector4d::Zero();
  delta[k] = step;
  Line plus;
  ceres::LineManifold<3>().Plus(line.data(), delta.data(), plus.data());
  return plus;
}

Line Transformed(const SE3& cam_from_world, const Line& line) {
  const Eigen::Vector3d o = cam_from_world * Eigen::Vector3d(line[0], line[1], line[2]);
  const Eigen::Vector3d d = cam_from_world.rotation() * Eigen::Vector3d(line[3], line[4], line[5]);
  return MakeLine(o, d);
}

}  // namespace

KeyframeLine LineInCamera(const SE3& cam_from_world, const Eigen::Vector3d& point_in_world,
                          const Eigen::Vector3d& direction_in_world,
                          const Eigen::Matrix4d& tangent_covariance_in_world, int edge_id) {
  const Line world = MakeLine(point_in_world, direction_in_world);
  const Line cam = Transformed(cam_from_world, world);
  const ceres::LineManifold<3> manifold;
  Eigen::Matrix4d g;
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector4d plus, minus;
    manifold.Minus(Transformed(cam_from_world, Perturbed(world, k, kTangentStep)).data(),
                   cam.data(), plus.data());
    manifold.Minus(Transformed(cam_from_world, Perturbed(world, k, -kTangentStep)).data(),
                   cam.data(), minus.data());
    g.col(k) = (plus - minus) / (2.0 * kTangentStep);
  }
  KeyframeLine result;
  result.edge_id = edge_id;
  result.point = Eigen::Vector3d(cam[0], cam[1], cam[2]);
  result.direction = Eigen::Vector3d(cam[3], cam[4], cam[5]);
  result.tangent_covariance = g * tangent_covariance_in_world * g.transpose();
  return result;
}

bool RayLineInverseDepth(const PinholeCamera& camera, const Eigen::Vector2d& pixel,
                         const Eigen::Vector3d& point, const Eigen::Vector3d& direction,
                         double max_miss_ratio, double* idepth) {
  const Eigen::Vector3d r = camera.Unproject(pixel);
  const double a = r.dot(r), b = r.dot(direction), c = direction.dot(direction);
  const double e = r.dot(point), f = direction.dot(point);
  const double den = a * c - b * b;
  if (!(den > kMinSinAngle * kMinSinAngle * a * c)) return false;
  const double s = (c * e - b * f) / den;
  const double t = (b * e - a * f) / den;
  if (!(s > 0.0)) return false;
  const double miss = (s * r - point - t * direction).norm();
  if (miss > max_miss_ratio * s) return false;
  *idepth = 1.0 / s;
  return true;
}

bool RayLineInverseDepthAndVariance(const PinholeCamera& camera, const Eigen::Vector2d& pixel,
                                    const KeyframeLine& line, double max_miss_ratio, double* idepth,
                                    double* idepth_var) {
  const Line base = MakeLine(line.point, line.direction);
  double value;
  if (!RayLineInverseDepth(camera, pixel, line.point, line.direction, max_miss_ratio, &value)) {
    return false;
  }
  Eigen::RowVector4d jacobian;
  for (int k = 0; k < 4; ++k) {
    double plus, minus;
    const Line p = Perturbed(base, k, kTangentStep), m = Perturbed(base, k, -kTangentStep);
    if (!RayLineInverseDepth(camera, pixel, Eigen::Vector3d(p[0], p[1], p[2]),
                             Eigen::Vector3d(p[3], p[4], p[5]), kAnyMiss, &plus) ||
        !RayLineInverseDepth(camera, pixel, Eigen::Vector3d(m[0], m[1], m[2]),
                             Eigen::Vector3d(m[3], m[4], m[5]), kAnyMiss, &minus)) {
      return false;
    }
    jacobian[k] = (plus - minus) / (2.0 * kTangentStep);
  }
  *idepth = value;
  *idepth_var = jacobian * line.tangent_covariance * jacobian.transpose();
  return std::isfinite(*idepth_var);
}

}  // namespace pldvo
