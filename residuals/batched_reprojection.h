// Shared pieces of the batched residuals (photometric_residual, point_to_line_residual): the
// reprojection of reference rays with their inverse depths into the current frame, and the
// count of valid rows. Header-only; not a public interface.
#ifndef PLDVO_RESIDUALS_BATCHED_REPROJECTION_H_
#define PLDVO_RESIDUALS_BATCHED_REPROJECTION_H_

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

// pixel_i = pi(R * ray_in_ref_i + idepth_i * t) for cur_from_ref = [R | t]; NaN (both
// coordinates) for a point not in front of the current camera (q.z <= 0). `Observation` has a
// member `double idepth`; observations[i] belongs to rays_in_ref[i]. When `valid` is given it
// receives the residual's row validity, computed by
// `evaluate_valid(double* residuals, std::uint8_t* valid)` (the residual's EvaluateTangent).
template <typename Observation, typename EvaluateValid>
std::vector<Eigen::Vector2d> ReprojectRays(const PinholeCamera& camera,
                                           const std::vector<Eigen::Vector3d>& rays_in_ref,
                                           const std::vector<Observation>& observations,
                                           const SE3& cur_from_ref,
                                           std::vector<std::uint8_t>* valid,
                                           EvaluateValid evaluate_valid) {
  if (valid != nullptr) {
    std::vector<double> residuals(observations.size());
    std::vector<std::uint8_t> row_valid(observations.size());
    evaluate_valid(residuals.data(), row_valid.data());
    *valid = std::move(row_valid);
  }
  const Eigen::Matrix3d rotation = cur_from_ref.rotation_matrix();
  std::vector<Eigen::Vector2d> pixels(observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    const Eigen::Vector3d q =
        rotation * rays_in_ref[i] + observations[i].idepth * cur_from_ref.translation();
    pixels[i] = q.z() > 0.0 ? camera.Project(q)
                            : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return pixels;
}

// The number of nonzero flags.
inline int CountValid(const std::vector<std::uint8_t>& valid) {
  int count = 0;
  for (const std::uint8_t v : valid) count += v;
  return count;
}

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_BATCHED_REPROJECTION_H_
