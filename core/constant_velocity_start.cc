#include "core/constant_velocity_start.h"

#include <Eigen/Core>
#include <stdexcept>

namespace pldvo {

int ConstantVelocityStartPoses(const Trajectory& trajectory, double relative_tolerance,
                               int min_steps) {
  if (!(relative_tolerance >= 0.0)) {
    throw std::invalid_argument("constant-velocity start: the tolerance must be >= 0");
  }
  if (min_steps < 1) throw std::invalid_argument("constant-velocity start: min_steps must be >= 1");
  auto velocity = [&](size_t i) -> Eigen::Vector3d {
    const double dt = trajectory[i].timestamp - trajectory[i - 1].timestamp;
    if (!(dt > 0.0)) {
      throw std::invalid_argument("constant-velocity start: timestamps must increase");
    }
    return (trajectory[i].world_from_cam.translation() -
            trajectory[i - 1].world_from_cam.translation()) /
           dt;
  };
  if (trajectory.size() < 2) return 0;
  Eigen::Vector3d previous = velocity(1);
  if (previous.norm() < 1e-6) return 0;
  size_t steps = 1;
  while (steps + 1 < trajectory.size()) {
    const Eigen::Vector3d next = velocity(steps + 1);
    if ((next - previous).norm() > relative_tolerance * previous.norm()) break;
    previous = next;
    ++steps;
  }
  return static_cast<int>(steps) >= min_steps ? static_cast<int>(steps) + 1 : 0;
}

}  // namespace pldvo
