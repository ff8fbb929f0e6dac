// A top view of trajectories as a hand-written SVG (no plotting dependency): the ground truth and
// any number of Sim(3)-aligned estimates, projected onto the plane of the ground truth's two
// principal axes (the plane it spans most, "top view" for a camera moving over a floor or along
// a road), equal scale on both axes, with a legend.
#ifndef PLDVO_CORE_TRAJECTORY_SVG_H_
#define PLDVO_CORE_TRAJECTORY_SVG_H_

#include <Eigen/Core>
#include <string>
#include <vector>

namespace pldvo {

struct SvgCurve {
  std::string label;
  std::vector<Eigen::Vector3d> positions;  // in the ground-truth frame (already aligned)
};

// Writes the SVG; throws std::runtime_error naming the path when it cannot be written.
// `ground_truth` may be empty (then the plane comes from the first curve).
void WriteTrajectorySvg(const std::string& path, const std::string& title,
                        const std::vector<Eigen::Vector3d>& ground_truth,
                        const std::vector<SvgCurve>& estimates);

}  // namespace pldvo

#endif  // PLDVO_CORE_TRAJECTORY_SVG_H_
