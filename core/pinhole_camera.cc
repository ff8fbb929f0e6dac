#include "core/pinhole_camera.h"

#include <cmath>
#include <sstream>

namespace pldvo {

Eigen::Matrix<double, 2, 3> PinholeCamera::ProjectJacobian(
    const Eigen::Vector3d& point_in_cam) const {
  const double inv_z = 1.0 / point_in_cam.z();
  Eigen::Matrix<double, 2, 3> jacobian;
  jacobian << fx * inv_z, 0.0, -fx * point_in_cam.x() * inv_z * inv_z, 0.0, fy * inv_z,
      -fy * point_in_cam.y() * inv_z * inv_z;
  return jacobian;
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

PinholeCamera PinholeCamera::AtLevel(int level) const {
  PinholeCamera scaled = *this;
  for (int i = 0; i < level; ++i) {
    scaled.width /= 2;
    scaled.height /= 2;
    scaled.fx *= 0.5;
    scaled.fy *= 0.5;
    scaled.cx = (scaled.cx + 0.5) * 0.5 - 0.5;
    scaled.cy = (scaled.cy + 0.5) * 0.5 - 0.5;
  }
  return scaled;
}

std::string PinholeCamera::Check() const {
  std::ostringstream error;
  if (width <= 0 || height <= 0)
    error << "image size must be positive, got " << width << "x" << height << "; ";
  // Bounds the undistortion maps and border scans a calibration file can request (a typo like
  // "width: 6400000" would otherwise exhaust memory or hang); 8K UHD and 20 MP fit.
  constexpr int kMaxSide = 32768;
  constexpr long long kMaxPixels = 1LL << 25;
  if (width > kMaxSide || height > kMaxSide ||
      static_cast<long long>(width) * height > kMaxPixels) {
    error << "image size " << width << "x" << height << " exceeds the supported " << kMaxSide
          << " px per side and " << kMaxPixels << " pixels; ";
  }
  if (!(fx > 0.0) || !(fy > 0.0) || !std::isfinite(fx) || !std::isfinite(fy)) {
    error << "focal lengths must be positive and finite, got fx=" << fx << " fy=" << fy << "; ";
  }
  if (!std::isfinite(cx) || !std::isfinite(cy)) error << "principal point must be finite; ";
  return error.str();
}

}  // namespace pldvo
