#include "backend/odometry/corner_epipolar_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <set>

namespace pldvo {
namespace {

// The consensus: five-point RANSAC as the two-view start's (OpenCV's confidence, 1 px).
constexpr double kConsensusConfidence = 0.999;
constexpr double kConsensusThresholdPx = 1.0;

}  // namespace

CornerConsensus FindCornerConsensus(const CornerTracks& tracks, const PinholeCamera& camera,
                                    int num_frames) {
  CornerConsensus consensus;
  consensus.focal_px = std::sqrt(camera.fx * camera.fy);
  std::set<int> anchors;
  for (size_t i = 0; i < tracks.positions.size(); ++i) anchors.insert(tracks.Anchor(i));
  std::vector<cv::Point2d> in_0, in_k;
  for (const int a : anchors) {
    for (int k = a + 1; k < num_frames; ++k) {
      // The anchor's tracks alive at k, on the normalised plane.
      in_0.clear();
      in_k.clear();
      for (size_t i = 0; i < tracks.positions.size(); ++i) {
        const std::vector<cv::Point2f>& track = tracks.positions[i];
        if (tracks.Anchor(i) != a || static_cast<int>(track.size()) <= k - a) continue;
        const cv::Point2f& first = track[0];
        const cv::Point2f& last = track[k - a];
        const Eigen::Vector3d x0 = camera.Unproject(Eigen::Vector2d(first.x, first.y));
        const Eigen::Vector3d xk = camera.Unproject(Eigen::Vector2d(last.x, last.y));
        in_0.emplace_back(x0.x(), x0.y());
        in_k.emplace_back(xk.x(), xk.y());
      }
      if (static_cast<int>(in_0.size()) < kMinEpipolarCorners) continue;
      cv::Mat inliers;
      const cv::Mat fitted = cv::findEssentialMat(
          in_0, in_k, 1.0, cv::Point2d(0.0, 0.0), cv::RANSAC, kConsensusConfidence,
          kConsensusThresholdPx / consensus.focal_px, inliers);
      CornerConsensus::Frame frame;
      frame.anchor = a;
      frame.k = k;
      for (size_t i = 0; i < in_0.size(); ++i) {
        if (!fitted.empty() && !inliers.at<uchar>(static_cast<int>(i))) continue;
        frame.in_0.emplace_back(in_0[i].x, in_0[i].y);
        frame.in_k.emplace_back(in_k[i].x, in_k[i].y);
      }
      if (static_cast<int>(frame.in_0.size()) >= kMinEpipolarCorners) {
        consensus.frames.push_back(std::move(frame));
      }
    }
  }
  return consensus;
}

double CornerEpipolarErrorPx(const CornerConsensus& consensus,
                             const std::vector<SE3>& world_from_cam) {
  double sum = 0.0;
  int counted = 0;
  std::vector<double> distances;
  for (const CornerConsensus::Frame& frame : consensus.frames) {
    if (frame.k >= static_cast<int>(world_from_cam.size())) continue;
    const SE3 cam_k_from_anchor = world_from_cam[frame.k].Inverse() * world_from_cam[frame.anchor];
    const Eigen::Vector3d t = cam_k_from_anchor.translation();
    if (!(t.norm() > 0.0)) continue;
    const Eigen::Vector3d u = t.normalized();
    Eigen::Matrix3d skew;
    skew << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
    const Eigen::Matrix3d essential = skew * cam_k_from_anchor.rotation().toRotationMatrix();
    distances.clear();
    for (size_t i = 0; i < frame.in_0.size(); ++i) {
      const Eigen::Vector3d x0 = frame.in_0[i].homogeneous(), xk = frame.in_k[i].homogeneous();
      const Eigen::Vector3d line_k = essential * x0, line_0 = essential.transpose() * xk;
      const double gradient_sq = line_k.head<2>().squaredNorm() + line_0.head<2>().squaredNorm();
      if (!(gradient_sq > 0.0)) continue;
      distances.push_back(consensus.focal_px * std::abs(xk.dot(line_k)) / std::sqrt(gradient_sq));
    }
    if (static_cast<int>(distances.size()) < kMinEpipolarCorners) continue;
    auto median = distances.begin() + distances.size() / 2;
    std::nth_element(distances.begin(), median, distances.end());
    sum += *median;
    ++counted;
  }
  return counted > 0 ? sum / counted : std::numeric_limits<double>::quiet_NaN();
}

double CornerEpipolarErrorPx(const CornerTracks& tracks, const std::vector<SE3>& world_from_cam,
                             const PinholeCamera& camera) {
  const int num_frames = static_cast<int>(world_from_cam.size());
  return CornerEpipolarErrorPx(FindCornerConsensus(tracks, camera, num_frames), world_from_cam);
}

}  // namespace pldvo
