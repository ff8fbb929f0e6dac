#include "backend/odometry/two_view_bootstrap.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/covariance.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "backend/mapping/depth_map_io.h"
#include "backend/mapping/depth_mapper.h"
#include "backend/odometry/brightness_change.h"
#include "backend/odometry/windowed_ba_keyframes.h"
#include "backend/windowed_ba/windowed_ba_solver.h"
#include "core/image_pyramid.h"
#include "core/statistics.h"
#include "core/wall_clock.h"

namespace pldvo {
namespace {

// Corner detection and tracking (OpenCV's defaults where it has them).
constexpr int kMaxCorners = 1000;
constexpr int kLkWindowPx = 21;
constexpr int kLkLevels = 3;
// A track survives a frame when tracking back lands within this of where it started.
constexpr double kForwardBackwardPx = 1.0;
// Five-point RANSAC (OpenCV's defaults).
constexpr double kRansacConfidence = 0.999;
constexpr double kRansacThresholdPx = 1.0;
// Bundle adjustment: Huber scale of the reprojection error and iteration cap.
constexpr double kHuberPx = 1.0;
constexpr int kMaxBundleIterations = 50;
// The adjustment that tests a second view (at every frame that passes the parallax gates) takes
// at most this many corners and frames, evenly spread: its cost grows with their product.
constexpr int kMaxTestCorners = 200;
constexpr int kMaxTestFrames = 8;
// The photometric refinement: frame 0's points (DSO's per-window budget) and LM iterations; its
// frames are chosen as the test adjustment's.
constexpr int kPhotometricPoints = 2000;
constexpr int kPhotometricIterations = 50;

cv::Mat ToGray8(const cv::Mat& image) {
  cv::Mat gray;
  image.convertTo(gray, CV_8U);
  return gray;
}

// One corner followed through the frames from its anchor: its position in every frame so far.
struct Track {
  std::vector<cv::Point2f> positions;
  int anchor = 0;  // the frame of positions[0]
};

// The live tracks' positions in `next` (forward-backward checked; ok[i] says which survived).
std::vector<cv::Point2f> TrackPoints(const cv::Mat& previous, const cv::Mat& next,
                                     const std::vector<cv::Point2f>& from, std::vector<bool>* ok) {
  std::vector<cv::Point2f> to, back;
  std::vector<uchar> found, found_back;
  std::vector<float> error;
  const cv::Size window(kLkWindowPx, kLkWindowPx);
  cv::calcOpticalFlowPyrLK(previous, next, from, to, found, error, window, kLkLevels);
  cv::calcOpticalFlowPyrLK(next, previous, to, back, found_back, error, window, kLkLevels);
  ok->assign(from.size(), false);
  for (size_t i = 0; i < from.size(); ++i) {
    const cv::Point2f d = back[i] - from[i];
    const bool inside = to[i].x >= 0.f && to[i].y >= 0.f && to[i].x <= next.cols - 1.f &&
                        to[i].y <= next.rows - 1.f;
    (*ok)[i] = found[i] && found_back[i] && inside && std::hypot(d.x, d.y) <= kForwardBackwardPx;
  }
  return to;
}

// Tracks every live track into `next_image` and moves the lost ones to `lost`; returns the frame
// as 8-bit gray in `previous`'s intensities. LK has no gain term, so the tracks first follow the
// frame scaled to `previous`'s mean and spread (which moves with what the camera sees), their
// patches fit the exposure change, and the tracks follow the frame with that change undone (if
// it moves a gray level).
cv::Mat TrackInto(const cv::Mat& previous, const cv::Mat& next_image, std::vector<Track>* tracks,
                  std::vector<Track>* lost) {
  std::vector<cv::Point2f> from;
  for (const Track& track : *tracks) from.push_back(track.positions.back());
  if (from.empty()) return ToGray8(next_image);
  cv::Scalar previous_mean, previous_std, next_mean, next_std;
  cv::meanStdDev(previous, previous_mean, previous_std);
  cv::meanStdDev(next_image, next_mean, next_std);
  BrightnessChange spread;
  if (previous_std[0] > 0.0 && next_std[0] > 0.0) {
    spread.gain = next_std[0] / previous_std[0];
    spread.offset = next_mean[0] - spread.gain * previous_mean[0];
  }
  std::vector<bool> ok;
  const std::vector<cv::Point2f> rough =
      TrackPoints(previous, UndoBrightnessChange(next_image, spread), from, &ok);
  std::vector<cv::Point2f> pairs_previous, pairs_next;
  for (size_t i = 0; i < from.size(); ++i) {
    if (!ok[i]) continue;
    pairs_previous.push_back(from[i]);
    pairs_next.push_back(rough[i]);
  }
  const BrightnessChange change =
      FitBrightnessChange(previous, next_image, pairs_previous, pairs_next);
  const cv::Mat next =
      ChangesGrayLevels(change) ? UndoBrightnessChange(next_image, change) : ToGray8(next_image);
  const std::vector<cv::Point2f> to = TrackPoints(previous, next, from, &ok);
  std::vector<Track> kept;
  for (size_t i = 0; i < tracks->size(); ++i) {
    if (!ok[i]) {
      lost->push_back(std::move((*tracks)[i]));
      continue;
    }
    kept.push_back(std::move((*tracks)[i]));
    kept.back().positions.push_back(to[i]);
  }
  *tracks = std::move(kept);
  return next;
}

// The relative pose frame_k <- frame_0 and the triangulated corners (frame 0 coordinates) of the
// essential-matrix inliers in front of both cameras.
struct TwoViewGeometry {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;          // unit length
  std::vector<int> track_ids;           // the inliers' indices into the tracks
  std::vector<Eigen::Vector3d> points;  // their triangulated positions
  double median_parallax_deg = 0.0;
  double rotation_free_parallax_px = 0.0;
};

TwoViewGeometry EstimateTwoViewGeometry(const std::vector<Track>& tracks, const cv::Matx33d& K) {
  TwoViewGeometry geometry;
  std::vector<cv::Point2f> p0, pk;
  for (const Track& track : tracks) {
    p0.push_back(track.positions.front());
    pk.push_back(track.positions.back());
  }
  cv::Mat mask;
  const cv::Mat E =
      cv::findEssentialMat(p0, pk, K, cv::RANSAC, kRansacConfidence, kRansacThresholdPx, mask);
  if (E.rows != 3 || E.cols != 3) return geometry;  // degenerate or several solutions
  cv::Mat R, t, points4;
  // Points farther than this (in baselines) count as behind: pure rotation gives none in front.
  constexpr double kMaxDistanceBaselines = 1000.0;
  cv::recoverPose(E, p0, pk, K, R, t, kMaxDistanceBaselines, mask, points4);
  points4.convertTo(points4, CV_64F);
  cv::cv2eigen(R, geometry.rotation);
  cv::cv2eigen(t, geometry.translation);
  std::vector<double> parallax_deg;
  const Eigen::Vector3d centre_k = -geometry.rotation.transpose() * geometry.translation;
  for (int i = 0; i < mask.rows; ++i) {
    if (!mask.at<uchar>(i)) continue;
    const double w = points4.at<double>(3, i);
    const Eigen::Vector3d X(points4.at<double>(0, i) / w, points4.at<double>(1, i) / w,
                            points4.at<double>(2, i) / w);
    const double cos_angle = X.normalized().dot((X - centre_k).normalized());
    geometry.track_ids.push_back(i);
    geometry.points.push_back(X);
    parallax_deg.push_back(std::acos(std::clamp(cos_angle, -1.0, 1.0)) * 180.0 / M_PI);
  }
  if (!parallax_deg.empty()) geometry.median_parallax_deg = Median(parallax_deg);
  std::vector<cv::Point2f> inliers_0, inliers_k;
  for (int i : geometry.track_ids) {
    inliers_0.push_back(p0[i]);
    inliers_k.push_back(pk[i]);
  }
  geometry.rotation_free_parallax_px = RotationFreeParallaxPx(inliers_0, inliers_k, K);
  return geometry;
}

// Reprojection error of a point X (frame 0 coordinates) in a frame with pose
// cam_from_ref = (q, t): pi(q X + t) - x, pixels.
struct ReprojectionError {
  ReprojectionError(const cv::Point2f& observed, const cv::Matx33d& K) : x(observed), K(K) {}
  template <class T>
  bool operator()(const T* q, const T* t, const T* X, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Matrix<T, 3, 1> p = rotation * Eigen::Map<const Eigen::Matrix<T, 3, 1>>(X) +
                                     Eigen::Map<const Eigen::Matrix<T, 3, 1>>(t);
    residual[0] = K(0, 0) * p.x() / p.z() + K(0, 2) - T(x.x);
    residual[1] = K(1, 1) * p.y() / p.z() + K(1, 2) - T(x.y);
    return true;
  }
  cv::Point2f x;
  cv::Matx33d K;
};

// Bundle adjustment of the poses of `frames` (ascending, from 0 to k; frame 0 fixed at the
// identity) and of the corners `track_ids` over all their observations in those frames; pose j
// is that of frames[j]. Gauge: frame 0 fixed and frame k's translation on a sphere
// (SphereManifold keeps its norm). With `direction_std`, returns the standard deviation of frame
// k's translation direction, deg: the larger of the two in the sphere's tangent plane, from the
// covariance at the solution for 1 px reprojection noise (infinite when the covariance is
// rank-deficient); else 0.
double BundleAdjust(const std::vector<Track>& tracks, const std::vector<int>& track_ids,
                    const std::vector<int>& frames, const cv::Matx33d& K,
                    std::vector<Eigen::Quaterniond>* rotations,
                    std::vector<Eigen::Vector3d>* translations,
                    std::vector<Eigen::Vector3d>* points, bool direction_std) {
  const int last = static_cast<int>(frames.size()) - 1;
  ceres::HuberLoss loss(kHuberPx);  // one for every residual block
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (int j = 0; j <= last; ++j) {
    problem.AddParameterBlock((*rotations)[j].coeffs().data(), 4,
                              new ceres::EigenQuaternionManifold());
    problem.AddParameterBlock((*translations)[j].data(), 3);
  }
  problem.SetParameterBlockConstant((*rotations)[0].coeffs().data());
  problem.SetParameterBlockConstant((*translations)[0].data());
  problem.SetManifold((*translations)[last].data(), new ceres::SphereManifold<3>());
  for (size_t i = 0; i < track_ids.size(); ++i) {
    for (int j = 0; j <= last; ++j) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ReprojectionError, 2, 4, 3, 3>(
              new ReprojectionError(tracks[track_ids[i]].positions[frames[j]], K)),
          &loss, (*rotations)[j].coeffs().data(), (*translations)[j].data(), (*points)[i].data());
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.max_num_iterations = kMaxBundleIterations;
  options.logging_type = ceres::SILENT;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!direction_std) return 0.0;

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  ceres::Covariance covariance(covariance_options);
  const std::vector<const double*> blocks{(*translations)[last].data()};
  Eigen::Matrix2d tangent_covariance;  // row-major and column-major alike (symmetric)
  if (!covariance.Compute(blocks, &problem) ||
      !covariance.GetCovarianceMatrixInTangentSpace(blocks, tangent_covariance.data())) {
    return std::numeric_limits<double>::infinity();
  }
  // |t_k| = 1: a tangent step of s turns the direction by s radians.
  const double largest_variance =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(tangent_covariance).eigenvalues()(1);
  return std::sqrt(std::max(largest_variance, 0.0)) * 180.0 / M_PI;
}

// The poses (cam_from_ref) of `frames` interpolated between the identity (frame 0) and the
// two-view pose of the last frame k (slerp / linear in frame / k), the bundle adjustment's start.
void InterpolatePoses(const TwoViewGeometry& geometry, const std::vector<int>& frames,
                      std::vector<Eigen::Quaterniond>* rotations,
                      std::vector<Eigen::Vector3d>* translations) {
  const Eigen::Quaterniond rotation_k(geometry.rotation);
  rotations->clear();
  translations->clear();
  for (int frame : frames) {
    const double f = static_cast<double>(frame) / frames.back();
    rotations->push_back(Eigen::Quaterniond::Identity().slerp(f, rotation_k));
    translations->push_back(f * geometry.translation);
  }
}

// At most `count` of 0..size - 1, evenly spaced, the first and the last among them.
std::vector<int> EvenlySpaced(int size, int count) {
  std::vector<int> indices(std::min(size, count));
  if (size <= count) {
    std::iota(indices.begin(), indices.end(), 0);
  } else {
    for (int i = 0; i < count; ++i) {
      indices[i] = static_cast<int>(std::lround(i * (size - 1.0) / (count - 1)));
    }
  }
  return indices;
}

}  // namespace

double RotationFreeParallaxPx(const std::vector<cv::Point2f>& x0,
                              const std::vector<cv::Point2f>& xk, const cv::Matx33d& K) {
  if (x0.size() != xk.size()) {
    throw std::invalid_argument("RotationFreeParallaxPx: x0 and xk differ in size");
  }
  if (x0.size() < 3) return 0.0;
  const auto ray = [&K](const cv::Point2f& x) {
    return Eigen::Vector3d((x.x - K(0, 2)) / K(0, 0), (x.y - K(1, 2)) / K(1, 1), 1.0).normalized();
  };
  // Kabsch: the rotation R maximising sum ray_k^T R ray_0 is U diag(1, 1, det) V^T of the SVD of
  // sum ray_k ray_0^T.
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < x0.size(); ++i) correlation += ray(xk[i]) * ray(x0[i]).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * sign * svd.matrixV().transpose();
  const double focal_px = std::sqrt(K(0, 0) * K(1, 1));
  std::vector<double> parallax_px;
  for (size_t i = 0; i < x0.size(); ++i) {
    const double cos_angle = ray(xk[i]).dot(rotation * ray(x0[i]));
    parallax_px.push_back(focal_px * std::acos(std::clamp(cos_angle, -1.0, 1.0)));
  }
  return Median(parallax_px);
}

// The frames between two refined ones (`refined`, increasing) take the correction of their poses
// interpolated on SE(3): poses[j] = Exp((1 - w) Log(C_a) + w Log(C_b)) before[j], C = refined
// pose * pose before^-1 of the neighbours a < j < b, w = (j - a) / (b - a).
void InterpolateCorrections(const std::vector<int>& refined, const std::vector<SE3>& before,
                            std::vector<SE3>* poses) {
  for (size_t n = 0; n + 1 < refined.size(); ++n) {
    const int a = refined[n];
    const int b = refined[n + 1];
    const Vector6d log_a = ((*poses)[a] * before[a].Inverse()).Log();
    const Vector6d log_b = ((*poses)[b] * before[b].Inverse()).Log();
    for (int j = a + 1; j < b; ++j) {
      const double w = static_cast<double>(j - a) / (b - a);
      (*poses)[j] = SE3::Exp((1.0 - w) * log_a + w * log_b) * before[j];
    }
  }
}

// Step 5: frames `frames` (0 first, at the identity) and the observed hypotheses of frame 0's
// map adjusted by the windowed BA's photometric residuals (eq. 2, frame 0 hosting every point,
// affine brightness, DSO's outlier test at outlier_factor, 0: off); frame 0 and the baseline to
// the next frame hold the gauge. No inverse-depth prior: the map's variances come from the poses
// being corrected. Replaces the refined frames' poses and returns the points adjusted; 0 when it
// failed.
int RefinePhotometrically(const std::vector<cv::Mat>& images, const SemiDenseDepthMap& map,
                          const PinholeCamera& camera, const std::vector<int>& frames,
                          double outlier_factor, std::vector<SE3>* poses) {
  WindowedBAWindow window;
  window.camera = camera;
  for (const int j : frames) {
    WindowedBAKeyframe keyframe;
    keyframe.id = j;
    keyframe.cam_from_world = (*poses)[j];
    keyframe.pyramid = std::make_shared<const ImagePyramid>(ToGray8(images[j]), 1);
    window.keyframes.push_back(std::move(keyframe));
  }
  window.keyframes.front().points = ObservedWindowPoints(map);
  WindowedBAOptions options;
  options.window = static_cast<int>(frames.size());
  options.max_points = kPhotometricPoints * options.window;  // the budget is split per frame
  options.lines = false;
  options.idepth_prior_scale = 0.0;
  // Set here, not inherited from the BA's defaults, which would move every two-view start when
  // they change (docs/bootstrap.md). With no depth prior V enters once: points whose depth is
  // uncertain weigh less (eq. 5).
  options.depth_variance_in_weights = true;
  options.outlier_energy_factor = outlier_factor;
  options.max_iterations = kPhotometricIterations;
  const WindowedBAResult result = RunWindowedBA(window, options);
  if (result.points.empty() || !(result.summary.final_cost <= result.summary.initial_cost)) {
    return 0;
  }
  for (const WindowedBAResultKeyframe& keyframe : result.keyframes) {
    (*poses)[keyframe.id] = keyframe.cam_from_world;
  }
  return static_cast<int>(result.points.size());
}

// Where frame 0's corners are lost before the random start's horizon: from the frame they were
// lost in (`previous`, its gray image), corners detected there are followed on, and again wherever
// the newest anchor's corners fall below two_view_min_inliers, up to frame horizon - 1. Every
// track, frame 0's included, goes to `out` with its anchor.
void TrackReanchoredCorners(const Dataset& dataset, const OdometryOptions& options, int lost_at,
                            int horizon, cv::Mat previous, std::vector<Track> tracks,
                            std::vector<Track> lost, CornerTracks* out) {
  int anchor = 0;
  for (int k = lost_at; k < horizon; ++k) {
    if (k > lost_at) previous = TrackInto(previous, dataset.Load(k).image, &tracks, &lost);
    const int alive = static_cast<int>(std::count_if(
        tracks.begin(), tracks.end(), [&](const Track& t) { return t.anchor == anchor; }));
    if (alive >= options.two_view_min_inliers || k + 1 >= horizon) continue;
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(previous, corners, kMaxCorners, options.two_view_corner_quality,
                            options.two_view_corner_min_distance_px);
    anchor = k;
    for (const cv::Point2f& corner : corners) tracks.push_back({{corner}, anchor});
  }
  out->positions.clear();
  out->anchors.clear();
  for (std::vector<Track>* set : {&lost, &tracks}) {
    for (Track& track : *set) {
      out->positions.push_back(std::move(track.positions));
      out->anchors.push_back(track.anchor);
    }
  }
}

int TwoViewRestartFrame(const TwoViewBootstrapFailure& failure, bool after_direction_gate) {
  if (failure.tracks_lost_at >= 0) return std::max(1, failure.tracks_lost_at);
  if (after_direction_gate && failure.first_gated >= 1) return failure.first_gated;
  return -1;
}

TwoViewBootstrap BootstrapFromTwoViews(const Dataset& dataset, const OdometryConfig& config,
                                       int num_frames, CornerTracks* unsettled_tracks) {
  const auto start = WallClock::now();
  const OdometryOptions& options = config.odometry;
  const int last = std::min(num_frames, options.two_view_max_frames + 1);
  if (last < 2) throw TwoViewBootstrapFailure("two-view bootstrap: fewer than two frames", -1);
  const PinholeCamera& camera = dataset.camera();
  const cv::Matx33d K(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);

  std::vector<cv::Mat> images{dataset.Load(0).image};
  cv::Mat previous = ToGray8(images[0]);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(previous, corners, kMaxCorners, options.two_view_corner_quality,
                          options.two_view_corner_min_distance_px);
  if (static_cast<int>(corners.size()) < options.two_view_min_inliers) {
    throw TwoViewBootstrapFailure("two-view bootstrap: frame 0 has " +
                                      std::to_string(corners.size()) +
                                      " corners, fewer than two_view_min_inliers",
                                  0);
  }
  std::vector<Track> tracks, lost;
  for (const cv::Point2f& corner : corners) tracks.push_back({{corner}});

  TwoViewBootstrap result;
  TwoViewGeometry geometry;
  std::vector<Eigen::Quaterniond> rotations;
  std::vector<Eigen::Vector3d> translations;
  std::vector<Eigen::Vector3d> points;
  // The frame with enough corners and the largest rotation-free parallax so far, and the smallest
  // direction uncertainty of a frame that passed the parallax gates (error message).
  std::string best = "none";
  double best_free_px = -1.0;
  double best_direction_std_deg = std::numeric_limits<double>::infinity();
  int tested = 0;           // frames that passed the parallax gates
  int first_gated = -1;     // the first of them
  int tracks_lost_at = -1;  // the frame where too few corners were left, if any
  // Frame 0's view of the adjusted directions to the camera centres of the latest consecutive
  // frames that passed the parallax gates (at most two_view_stable_frames).
  std::deque<Eigen::Vector3d> directions;
  for (int k = 1; k < last && result.second_view < 0; ++k) {
    images.push_back(dataset.Load(k).image);
    previous = TrackInto(previous, images.back(), &tracks, &lost);
    if (static_cast<int>(tracks.size()) < options.two_view_min_inliers) {
      tracks_lost_at = k;
      break;
    }
    geometry = EstimateTwoViewGeometry(tracks, K);
    const bool enough = static_cast<int>(geometry.points.size()) >= options.two_view_min_inliers;
    if (enough && geometry.rotation_free_parallax_px > best_free_px) {
      best_free_px = geometry.rotation_free_parallax_px;
      best = "frame " + std::to_string(k) + ": " + std::to_string(geometry.points.size()) +
             " corners, " + std::to_string(geometry.median_parallax_deg) + " deg, rotation-free " +
             std::to_string(best_free_px) + " px";
    }
    if (!enough || geometry.median_parallax_deg < options.two_view_min_parallax_deg ||
        geometry.rotation_free_parallax_px < options.two_view_min_rotation_free_parallax_px) {
      directions.clear();
      continue;
    }
    // The test adjustment (at most kMaxTestCorners corners over kMaxTestFrames frames). Frame k
    // is the second view when it fixes k's translation direction and the directions of the last
    // two_view_stable_frames frames agree: a wrong decomposition or a local minimum moves the
    // direction from one frame to the next by more than its uncertainty.
    std::vector<int> track_ids;
    points.clear();
    for (int i : EvenlySpaced(static_cast<int>(geometry.points.size()), kMaxTestCorners)) {
      track_ids.push_back(geometry.track_ids[i]);
      points.push_back(geometry.points[i]);
    }
    const std::vector<int> frames = EvenlySpaced(k + 1, kMaxTestFrames);
    InterpolatePoses(geometry, frames, &rotations, &translations);
    const double direction_std_deg =
        BundleAdjust(tracks, track_ids, frames, K, &rotations, &translations, &points, true);
    best_direction_std_deg = std::min(best_direction_std_deg, direction_std_deg);
    if (tested++ == 0) first_gated = k;
    directions.push_back(-(rotations.back().conjugate() * translations.back()).normalized());
    if (static_cast<int>(directions.size()) > options.two_view_stable_frames) {
      directions.pop_front();
    }
    const double max_deg = options.two_view_max_direction_std_deg;
    bool agree = static_cast<int>(directions.size()) == options.two_view_stable_frames;
    for (size_t i = 0; i < directions.size(); ++i) {
      for (size_t j = i + 1; j < directions.size(); ++j) {
        const double cos_angle = std::clamp(directions[i].dot(directions[j]), -1.0, 1.0);
        agree = agree && std::acos(cos_angle) * 180.0 / M_PI <= max_deg;
      }
    }
    if (direction_std_deg <= max_deg && agree) {
      result.second_view = k;
      result.direction_std_deg = direction_std_deg;
    }
  }
  if (result.second_view < 0) {
    std::string why = "no frame up to " + std::to_string(last - 1) + " has " +
                      std::to_string(options.two_view_min_inliers) +
                      " corners triangulated with a median parallax of " +
                      std::to_string(options.two_view_min_parallax_deg) +
                      " deg and a rotation-free parallax of " +
                      std::to_string(options.two_view_min_rotation_free_parallax_px) +
                      " px (largest rotation-free with enough corners: " + best + ")";
    const bool lost_tracks = tracks_lost_at >= 0;
    const std::string tracks_lost = std::to_string(tracks.size()) + " corners left at frame " +
                                    std::to_string(tracks_lost_at) +
                                    ", fewer than two_view_min_inliers";
    if (lost_tracks) why = tracks_lost;
    // The corners fix the direction roughly: the random start's choice checks its candidates
    // against them, where they last over its frames (a wrong start shows in the later ones).
    if (tested > 0 && (!lost_tracks || tracks_lost_at >= options.random_start_frames)) {
      if (unsettled_tracks != nullptr) {
        unsettled_tracks->positions.clear();
        unsettled_tracks->anchors.clear();
        for (std::vector<Track>* set : {&lost, &tracks}) {
          for (Track& track : *set) {
            unsettled_tracks->positions.push_back(std::move(track.positions));
          }
        }
      }
      why = (lost_tracks ? tracks_lost + "; no earlier frame" : "no frame") +
            " that passes the parallax gates fixes the translation direction to " +
            std::to_string(options.two_view_max_direction_std_deg) + " deg (best " +
            std::to_string(best_direction_std_deg) + " deg) with the " +
            std::to_string(options.two_view_stable_frames) +
            " last frames' directions agreeing to it";
    }
    // Lost before the random start's horizon: corners detected later check its later frames.
    const int horizon = std::min(num_frames, options.random_start_frames);
    if (options.random_start_reanchored_corners && unsettled_tracks != nullptr && lost_tracks &&
        tracks_lost_at < horizon) {
      TrackReanchoredCorners(dataset, options, tracks_lost_at, horizon, previous, std::move(tracks),
                             std::move(lost), unsettled_tracks);
      why += "; corners detected again from frame " + std::to_string(tracks_lost_at) +
             " check the random start";
    }
    throw TwoViewBootstrapFailure("two-view bootstrap: " + why, tracks_lost_at, first_gated);
  }
  result.tracks = static_cast<int>(tracks.size());
  result.inliers = static_cast<int>(geometry.points.size());
  result.parallax_deg = geometry.median_parallax_deg;
  result.rotation_free_parallax_px = geometry.rotation_free_parallax_px;
  const int k = result.second_view;

  // The second view's poses of frames 1..k and its corners, adjusted over every frame.
  std::vector<int> frames(k + 1);
  std::iota(frames.begin(), frames.end(), 0);
  InterpolatePoses(geometry, frames, &rotations, &translations);
  points = geometry.points;
  BundleAdjust(tracks, geometry.track_ids, frames, K, &rotations, &translations, &points, false);

  // Scale: median inverse depth of the corners in front of frame 0 is 1.
  std::vector<double> idepths;
  for (const Eigen::Vector3d& X : points) {
    if (X.z() > 0.0) idepths.push_back(1.0 / X.z());
  }
  if (idepths.empty()) {
    throw TwoViewBootstrapFailure("two-view bootstrap: no corner in front after the adjustment",
                                  -1);
  }
  const double scale = Median(idepths);

  // Frame 0's map, every hypothesis from the corners' median (or the random map: the option),
  // fused with frames 1..k in order (small baselines first, as in the run); each photometric pass
  // refines the poses and the map is estimated again from them.
  std::vector<SE3> poses;
  for (int j = 0; j <= k; ++j) poses.emplace_back(rotations[j], translations[j] * scale);
  MappingOptions map_options = config.mapping;
  if (options.two_view_map_prior == OdometryOptions::TwoViewMapPrior::kCornerMedian) {
    map_options.init = MappingOptions::Init::kConstant;
    map_options.init_idepth = 1.0;  // the corners' median after the scale
  }
  auto estimate_map = [&]() {
    auto mapper = std::make_unique<DepthMapper>(camera, map_options);
    mapper->InitializeKeyframe(images[0], EdgeTrace());
    for (int j = 1; j <= k; ++j) mapper->UpdateWithFrame(images[j], poses[j], {});
    return mapper;
  };
  std::unique_ptr<DepthMapper> mapper = estimate_map();
  const std::vector<int> refined = EvenlySpaced(k + 1, kMaxTestFrames);
  for (int pass = 0; pass < options.two_view_photometric_passes; ++pass) {
    const std::vector<SE3> unrefined = poses;
    const int adjusted = RefinePhotometrically(images, mapper->depth_map(), camera, refined,
                                               options.two_view_photometric_outlier_factor, &poses);
    if (adjusted == 0) break;
    result.photometric_points = adjusted;
    InterpolateCorrections(refined, unrefined, &poses);
    mapper = estimate_map();
  }

  double median_idepth = 0.0;  // of the map: `depth` is in units of 1 / median_idepth
  result.depth = NormalizedObservedDepth(mapper->depth_map(), &result.points, &median_idepth);
  if (result.depth.empty()) {
    throw TwoViewBootstrapFailure("two-view bootstrap: frame 0's map has no observed hypothesis",
                                  -1);
  }
  result.second_from_first = SE3(poses[k].rotation(), poses[k].translation() * median_idepth);
  result.ms = MsSince(start);
  return result;
}

}  // namespace pldvo
