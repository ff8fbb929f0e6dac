// libFuzzer target: TUM trajectories / groundtruth.txt (core/trajectory_io.h
// ReadTrajectoryTum). The input is the file. On accepted input: timestamps are finite and
// increasing, rotations unit, and WriteTrajectoryTum reads back with the same timestamps.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/trajectory_io.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  const std::string path = fuzz::ScratchDir() + "/groundtruth.txt";
  fuzz::WriteFile(path, data, size);
  Trajectory trajectory;
  if (!fuzz::RunParser([&] { trajectory = ReadTrajectoryTum(path); }, path)) return 0;
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const StampedPose& pose = trajectory[i];
    fuzz::Require(std::isfinite(pose.timestamp), "non-finite timestamp accepted");
    fuzz::Require(i == 0 || pose.timestamp > trajectory[i - 1].timestamp,
                  "non-increasing timestamps accepted");
    fuzz::Require(std::abs(pose.world_from_cam.rotation().norm() - 1.0) < 1e-9,
                  "rotation not normalised");
    fuzz::Require(pose.world_from_cam.translation().allFinite(), "non-finite translation");
  }
  const std::string copy_path = fuzz::ScratchDir() + "/copy.txt";
  WriteTrajectoryTum(trajectory, copy_path);
  Trajectory copy;
  if (!fuzz::RunParser([&] { copy = ReadTrajectoryTum(copy_path); }, "")) {
    fuzz::Finding("WriteTrajectoryTum output is rejected by ReadTrajectoryTum");
  }
  fuzz::Require(copy.size() == trajectory.size(), "round trip changes the pose count");
  for (size_t i = 0; i < copy.size(); ++i) {
    fuzz::Require(copy[i].timestamp == trajectory[i].timestamp, "round trip changes a timestamp");
  }
  return 0;
}
