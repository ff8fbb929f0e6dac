// Trajectories in the TUM format: one line per pose, `timestamp tx ty tz qx qy qz qw`, the pose
// being camera-to-world (world_from_cam). Lines starting with '#' are comments.
#ifndef PLDVO_CORE_TRAJECTORY_IO_H_
#define PLDVO_CORE_TRAJECTORY_IO_H_

#include <ostream>
#include <string>
#include <vector>

#include "core/se3.h"

namespace pldvo {

struct StampedPose {
  double timestamp = 0.0;  // seconds
  SE3 world_from_cam;
};
using Trajectory = std::vector<StampedPose>;

// Throws std::runtime_error naming the file and line of a malformed entry (wrong field count,
// non-numeric or non-finite value, non-unit quaternion, non-increasing timestamp).
Trajectory ReadTrajectoryTum(const std::string& path);
void WriteTrajectoryTum(const Trajectory& trajectory, const std::string& path);
// One line in TUM format with full precision (for writing as a run goes).
void WriteTumLine(const StampedPose& pose, std::ostream& out);

}  // namespace pldvo

#endif  // PLDVO_CORE_TRAJECTORY_IO_H_
