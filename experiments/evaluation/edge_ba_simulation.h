// Simulated edge bundle adjustment windows with ground truth, for tests, benchmarks and
// ablations (docs/edge_ba.md, "Measurements"): given ground-truth camera poses and 3D segments
// (e.g. experiments/synthetic's Scene::edges()), each keyframe observes every segment whose visible
// part projects to at least `min_length_px` pixels; its observation is `pixels_per_observation`
// pixels spread evenly along the visible projected segment with Gaussian noise. Occlusion is
// not modelled (purely geometric). Initial estimates are the ground truth perturbed by the
// given noise; the oldest pose is exact and the second keeps its ground-truth distance to the
// oldest, so estimates are comparable with the ground truth in the BA's gauge.
#ifndef PLDVO_EXPERIMENTS_EVALUATION_EDGE_BA_SIMULATION_H_
#define PLDVO_EXPERIMENTS_EVALUATION_EDGE_BA_SIMULATION_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "backend/edge_ba/edge_ba_window.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

struct EdgeBASimulationOptions {
  int pixels_per_observation = 24;
  double pixel_sigma = 0.5;           // px, per coordinate
  double min_length_px = 30.0;        // visible projected length for an observation
  double min_depth = 0.1;             // m; segments are clipped to z >= min_depth
  double pose_sigma_m = 0.02;         // translation noise of the initial poses, per axis
  double pose_sigma_rad = 0.0087;     // rotation noise (0.5 deg), per axis
  double line_sigma_m = 0.03;         // displacement of the initial lines across their direction
  double line_sigma_rad = 0.0175;     // rotation noise of their directions (1 deg), per axis
  bool provide_initial_lines = true;  // false: the BA triangulates every line
  std::uint64_t seed = 1;
};

struct EdgeBASimulation {
  EdgeBAWindow window;                      // noisy initial estimates and observations
  std::vector<SE3> cam_from_world_true;     // per window keyframe
  std::vector<Eigen::Vector3d> start_true;  // per segment index (= line id)
  std::vector<Eigen::Vector3d> end_true;
};

// `world_from_cam` gives the keyframes (oldest first; ids 0, 1, ...), `segments_start/end` the
// 3D segments in the world (line id = index).
EdgeBASimulation SimulateEdgeBAWindow(const PinholeCamera& camera,
                                      const std::vector<SE3>& world_from_cam,
                                      const std::vector<Eigen::Vector3d>& segments_start,
                                      const std::vector<Eigen::Vector3d>& segments_end,
                                      const EdgeBASimulationOptions& options);

// A hand-made, well-conditioned scene: `num_lines` segments (0.5-1.5 m long, uniformly random
// directions, midpoints uniform in [-2, 2] x [-1.5, 1.5] x [3, 6] m) and `num_keyframes`
// cameras looking along the world's +z, moving sideways along x by `spacing_m` per keyframe,
// with +-2 cm position jitter and +-2 deg rotations about each axis.
struct EdgeBAScene {
  std::vector<SE3> world_from_cam;
  std::vector<Eigen::Vector3d> start;
  std::vector<Eigen::Vector3d> end;
};
EdgeBAScene MakeRandomLineScene(int num_lines, int num_keyframes, double spacing_m,
                                std::uint64_t seed);

// Errors of estimates against the simulation's ground truth.
struct EdgeBAErrors {
  double position_rmse_m = 0.0;       // camera centres of the non-oldest keyframes
  double rotation_rmse_deg = 0.0;     // angle of R_est R_true^T
  double line_distance_rmse_m = 0.0;  // distance of the true endpoints to the estimated line
  double line_angle_rmse_deg = 0.0;   // angle between the directions
  // Medians of the same per-line errors (the RMSE is dominated by the few lines whose
  // back-projected planes are nearly parallel).
  double line_distance_median_m = 0.0;
  double line_angle_median_deg = 0.0;
  int num_lines = 0;
};
// Over the keyframes of `keyframes` (matched by id) and the lines of `lines` (matched by id).
EdgeBAErrors ComputeEdgeBAErrors(const EdgeBASimulation& simulation,
                                 const std::vector<EdgeBAResultKeyframe>& keyframes,
                                 const std::vector<EdgeBALine>& lines);
// The errors of the simulation's own initial estimates over the given line ids.
EdgeBAErrors InitialEdgeBAErrors(const EdgeBASimulation& simulation,
                                 const std::vector<int>& line_ids);

}  // namespace pldvo

#endif  // PLDVO_EXPERIMENTS_EVALUATION_EDGE_BA_SIMULATION_H_
