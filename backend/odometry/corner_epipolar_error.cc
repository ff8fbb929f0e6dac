#include "backend/odometry/corner_epipolar_error.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace pldvo {

double CornerEpipolarErrorPx(const CornerTracks& tracks, const std::vector<SE3>& world_from_cam,
                             const PinholeCamera& camera) {
  if (world_from_cam.empty()) return std::numeric_limits<double>::quiet_NaN();
  auto normalised = [&](const cv::Point2f& p) {
    return camera.Unproject(Eigen::Vector2d(p.x, p.y));
  };
  const double focal = std::sqrt(camera.fx * camera.fy);
  double sum = 0.0;
  int frames = 0;
  std::vector<double> distances;
  for (size_t k = 1; k < world_from_cam.size(); ++k) {
    const SE3 cam_k_from_cam0 = world_from_cam[k].Inverse() * world_from_cam[0];
    const Eigen::Vector3d t = cam_k_from_cam0.translation();
    if (!(t.norm() > 0.0)) continue;
    const Eigen::Vector3d u = t.normalized();
    Eigen::Matrix3d skew;
    skew << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
    const Eigen::Matrix3d essential = skew * cam_k_from_cam0.rotation().toRotationMatrix();
    distances.clear();
    for (const std::vector<cv::Point2f>& track : tracks.positions) {
      if (track.size() <= k) continue;
      const Eigen::Vector3d x0 = normalised(track[0]), xk = normalised(track[k]);
      const Eigen::Vector3d line_k = essential * x0, line_0 = essential.transpose() * xk;
      const double gradient_sq = line_k.head<2>().squaredNorm() + line_0.head<2>().squaredNorm();
      if (!(gradient_sq > 0.0)) continue;
      distances.push_back(focal * std::abs(xk.dot(line_k)) / std::sqrt(gradient_sq));
    }
    if (static_cast<int>(distances.size()) < kMinEpipolarCorners) continue;
    auto median = distances.begin() + distances.size() / 2;
    std::nth_element(distances.begin(), median, distances.end());
    sum += *median;
    ++frames;
  }
  return frames > 0 ? sum / frames : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace pldvo
