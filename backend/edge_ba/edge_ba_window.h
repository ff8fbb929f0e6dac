// The input and output of windowed edge bundle adjustment (docs/edge_ba.md): a self-contained
// snapshot of the newest keyframes with their observed edges, and the refined poses and lines.
// A snapshot owns copies of everything, so the tracking thread can hand it to the worker of
// EdgeBundleAdjuster and keep going.
//
// Line association: every observation names the 3D line (`line_id`) it belongs to; observations
// with the same line_id in different keyframes are the same line. `line_2d_id` is passed
// through untouched (the keyframe-local id of the traced 2D line, so the caller can map results
// back to its depth maps).
#ifndef PLDVO_BACKEND_EDGE_BA_EDGE_BA_WINDOW_H_
#define PLDVO_BACKEND_EDGE_BA_EDGE_BA_WINDOW_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// One 2D edge of a keyframe associated with a 3D line.
struct EdgeBAObservation {
  int line_id = -1;     // 3D line (association across keyframes)
  int line_2d_id = -1;  // keyframe-local 2D line id (passed through)
  // Edge pixels on the line at full resolution, in order along the edge (or just the 2D
  // segment's two endpoints). At least one.
  std::vector<Eigen::Vector2d> pixels;
  // Isotropic pixel noise (px); <= 0 takes EdgeBAOptions::default_sigma_px.
  double sigma_px = 0.0;
};

struct EdgeBAKeyframe {
  int id = -1;
  SE3 cam_from_world;
  std::vector<EdgeBAObservation> observations;
  // Optional motion prior (EdgeBAOptions::motion_prior): the pose of this keyframe relative to
  // the previous keyframe of the window as tracking measured it (previous_from_this).
  bool has_motion_prior = false;
  SE3 previous_from_this;
};

// A 3D line: any point on it and its direction (need not be unit), in the world.
struct EdgeBALine {
  int id = -1;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction_in_world = Eigen::Vector3d::UnitX();
  // Also observed by keyframes that have left the window (held constant when
  // EdgeBAOptions::lines_leaving_window == fixed).
  bool anchored = false;
};

struct EdgeBAWindow {
  PinholeCamera camera;  // full resolution, undistorted
  // Oldest first (strictly increasing ids). Only the newest EdgeBAOptions::window are used.
  std::vector<EdgeBAKeyframe> keyframes;
  // Initial estimates. A line_id observed but not listed is triangulated from its
  // observations (edge_ba_line_triangulation.h).
  std::vector<EdgeBALine> lines;
};

// Throws std::invalid_argument naming the offending keyframe / observation / line when the
// window is malformed (invalid camera, ids not increasing, duplicate line ids, empty or
// non-finite pixels, zero direction, non-finite pose).
void CheckEdgeBAWindow(const EdgeBAWindow& window);

enum class EdgeBALineStatus {
  kOptimized,  // a variable of the solve
  kFixed,      // anchored and held constant (its observations constrained the poses)
  kDropped,    // too few observing keyframes or too small a plane angle; returned unchanged
};

struct EdgeBAResultLine {
  EdgeBALine line;  // refined (or unchanged when not kOptimized); direction unit
  EdgeBALineStatus status = EdgeBALineStatus::kDropped;
  // kOptimized lines when EdgeBAResult::covariance_ok: the marginal covariance of the line's
  // tangent perturbation (LineManifold<3>::Plus at [point, direction], world frame), 4x4.
  bool has_covariance = false;
  Eigen::Matrix4d tangent_covariance = Eigen::Matrix4d::Zero();
};

struct EdgeBAResultKeyframe {
  int id = -1;
  SE3 cam_from_world;  // refined (unchanged for the gauge-fixed ones)
  bool fixed = false;  // held constant by the gauge
};

struct EdgeBAResult {
  long sequence = -1;    // EdgeBundleAdjuster's submission number (-1 for a direct solve)
  bool success = false;  // Ceres returned a usable solution
  std::string message;   // Ceres' termination message or why nothing was solved
  std::vector<EdgeBAResultKeyframe> keyframes;  // the window's keyframes, oldest first
  // Every line of the window by id, except dropped lines that were not listed in the input
  // (triangulation failed: no estimate to return).
  std::vector<EdgeBAResultLine> lines;
  // Statistics.
  int num_residuals = 0;
  int num_optimized_lines = 0;
  int num_fixed_lines = 0;
  int num_dropped_lines = 0;
  int iterations = 0;
  double initial_cost = 0.0;  // Ceres' 1/2 sum rho, whitened units
  double final_cost = 0.0;
  double build_seconds = 0.0;
  double solve_seconds = 0.0;
  // EdgeBAOptions::line_depth_feedback: the line covariances were computed (false when the
  // option is off, the solve failed or ceres::Covariance failed, e.g. rank-deficient).
  bool covariance_ok = false;
  double covariance_seconds = 0.0;  // attempted computations only
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_EDGE_BA_EDGE_BA_WINDOW_H_
