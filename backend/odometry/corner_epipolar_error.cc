#include "backend/odometry/corner_epipolar_error.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>

namespace pldvo {
namespace {

// The consensus: five-point RANSAC as the two-view start's (OpenCV's confidence, 1 px).
constexpr double kConsensusConfidence = 0.999;
constexpr double kConsensusThresholdPx = 1.0;

}  // namespace

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
    // The tracks alive at k, on the normalised plane, and which of them one motion explains.
    std::vector<cv::Point2d> in_0, in_k;
    for (const std::vector<cv::Point2f>& track : tracks.positions) {
      if (track.size() <= k) continue;
      const Eigen::Vector3d x0 = normalised(track[0]), xk = normalised(track[k]);
      in_0.emplace_back(x0.x(), x0.y());
      in_k.emplace_back(xk.x(), xk.y());
    }
    if (static_cast<int>(in_0.size()) < kMinEpipolarCorners) continue;
    cv::Mat consensus;
    const cv::Mat fitted =
        cv::findEssentialMat(in_0, in_k, 1.0, cv::Point2d(0.0, 0.0), cv::RANSAC,
                             kConsensusConfidence, kConsensusThresholdPx / focal, consensus);
    distances.clear();
    for (size_t i = 0; i < in_0.size(); ++i) {
      if (!fitted.empty() && !consensus.at<uchar>(static_cast<int>(i))) continue;
      const Eigen::Vector3d x0(in_0[i].x, in_0[i].y, 1.0), xk(in_k[i].x, in_k[i].y, 1.0);
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
