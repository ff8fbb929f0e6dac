// The ideal pinhole camera that every image is undistorted to before tracking.
// Pixel convention: integer coordinates are pixel centres, (0, 0) the centre of the top-left
// pixel; camera frame x right, y down, z forward.
#ifndef PLDVO_CORE_PINHOLE_CAMERA_H_
#define PLDVO_CORE_PINHOLE_CAMERA_H_

#include <Eigen/Core>
#include <string>

namespace pldvo {

struct PinholeCamera {
  int width = 0;
  int height = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;

  // u = fx x / z + cx, v = fy y / z + cy. The caller ensures z > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const {
    return Eigen::Vector2d(fx * point_in_cam.x() / point_in_cam.z() + cx,
                           fy * point_in_cam.y() / point_in_cam.z() + cy);
  }
  // d(u, v) / d(x, y, z).
  Eigen::Matrix<double, 2, 3> ProjectJacobian(const Eigen::Vector3d& point_in_cam) const;
  // The ray through a pixel, scaled to z = 1.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const {
    return Eigen::Vector3d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy, 1.0);
  }
  Eigen::Matrix3d K() const;
  // True when the pixel lies at least `border` pixels inside the image.
  bool IsInside(const Eigen::Vector2d& pixel, double border) const {
    return pixel.x() >= border && pixel.y() >= border && pixel.x() <= width - 1 - border &&
           pixel.y() <= height - 1 - border;
  }
  // The camera of pyramid level `level` (each level halves the resolution by 2x2 averaging, so
  // the pixel-centre convention gives c' = (c + 0.5) / 2 - 0.5).
  PinholeCamera AtLevel(int level) const;
  // Checks positive size (at most 32768 px a side and 2^25 pixels) and focal lengths; returns
  // an empty string or what is wrong.
  std::string Check() const;
};

}  // namespace pldvo

#endif  // PLDVO_CORE_PINHOLE_CAMERA_H_
