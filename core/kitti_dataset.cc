#include "core/kitti_dataset.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "core/camera_yaml.h"
#include "core/dataset_util.h"

namespace pldvo {
namespace {

using namespace dataset_util;  // NOLINT(build/namespaces): the readers' own helpers

// KITTI's poses keep R orthonormal to about 1e-6 (printed with 6+ significant digits); further
// off, the line is not a rotation.
constexpr double kMaxOrthonormalityError = 1e-3;

// calib.txt: "P0: p00 p01 ... p23" (3x4 row-major). The rectified left grey camera is the
// pinhole of P0; the image size comes from the first image.
PinholeCamera ReadP0(const std::string& path, int width, int height) {
  for (const TableLine& line : ReadTable(path)) {
    if (line.fields[0] != "P0:") continue;
    RequireFields(line, 13, 13, path, "'P0:' and 12 numbers");
    double p[12];
    for (int i = 0; i < 12; ++i) p[i] = ParseDouble(line.fields[i + 1], path, line.line_number);
    PinholeCamera camera;
    camera.width = width;
    camera.height = height;
    camera.fx = p[0];
    camera.cx = p[2];
    camera.fy = p[5];
    camera.cy = p[6];
    const std::string problem = camera.Check();
    if (!problem.empty()) FailAt(path, line.line_number, "P0: " + problem);
    return camera;
  }
  throw std::runtime_error(path + ": no 'P0:' line");
}

// KITTI poses: 12 numbers a line, the 3x4 row-major [R | t] of cam0-to-world, one per frame.
Trajectory ReadKittiPoses(const std::string& path, const std::vector<double>& timestamps) {
  Trajectory trajectory;
  const std::vector<TableLine> lines = ReadTable(path);
  for (const TableLine& line : lines) {
    RequireFields(line, 12, 12, path, "12 numbers (3x4 row-major [R | t])");
    double m[12];
    for (int i = 0; i < 12; ++i) m[i] = ParseDouble(line.fields[i], path, line.line_number);
    Eigen::Matrix3d rotation;
    rotation << m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10];
    if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() >
            kMaxOrthonormalityError ||
        rotation.determinant() < 0.0) {
      FailAt(path, line.line_number, "rotation is not orthonormal");
    }
    if (trajectory.size() >= timestamps.size()) {
      FailAt(path, line.line_number,
             "more poses than the " + std::to_string(timestamps.size()) + " frames");
    }
    StampedPose pose;
    pose.timestamp = timestamps[trajectory.size()];
    pose.world_from_cam = SE3(rotation, Eigen::Vector3d(m[3], m[7], m[11]));
    trajectory.push_back(pose);
  }
  if (trajectory.size() != timestamps.size()) {
    throw std::runtime_error(path + ": " + std::to_string(trajectory.size()) + " poses for " +
                             std::to_string(timestamps.size()) + " frames");
  }
  return trajectory;
}

// The poses file near a sequence folder .../sequences/NN: poses.txt in it, else
// ../../poses/NN.txt (KITTI's layout), else ../poses/NN.txt. Empty when none exists.
std::string FindPoses(const std::string& dir) {
  namespace fs = std::filesystem;
  fs::path folder = fs::absolute(dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();
  const std::string name = folder.filename().string() + ".txt";
  for (const fs::path& candidate :
       {folder / "poses.txt", folder.parent_path().parent_path() / "poses" / name,
        folder.parent_path() / "poses" / name}) {
    if (IsFile(candidate.string())) return candidate.string();
  }
  return "";
}

class KittiDataset : public ImageListDataset {
 public:
  KittiDataset(const std::string& dir, const DatasetOptions& options) {
    const std::string times = JoinPath(dir, "times.txt");
    if (!IsFile(times)) throw std::runtime_error(times + ": not found (kitti dataset)");
    for (const TableLine& line : ReadTable(times)) {
      RequireFields(line, 1, 1, times, "1 timestamp");
      const double t = ParseDouble(line.fields[0], times, line.line_number);
      if (!timestamps_.empty()) RequireIncreasing(timestamps_.back(), t, times, line.line_number);
      timestamps_.push_back(t);
    }
    if (timestamps_.empty()) throw std::runtime_error(times + ": lists no frames");
    const std::string image_dir = JoinPath(dir, "image_0");
    if (!IsDirectory(image_dir)) throw std::runtime_error(image_dir + ": not found (kitti)");
    paths_ = ListImages(image_dir);
    if (paths_.size() != timestamps_.size()) {
      throw std::runtime_error(times + ": " + std::to_string(timestamps_.size()) +
                               " timestamps for " + std::to_string(paths_.size()) + " images in " +
                               image_dir);
    }

    std::unique_ptr<CameraModel> model;
    if (!options.camera.empty()) {
      model = CameraFromPresetOrFile(options.camera);
    } else {
      const cv::Mat first = ReadGray8(paths_[0]);
      const std::string calib = JoinPath(dir, "calib.txt");
      if (!IsFile(calib)) throw std::runtime_error(calib + ": not found (kitti calibration)");
      const PinholeCamera pinhole = ReadP0(calib, first.cols, first.rows);
      model = MakeCameraModel("pinhole", pinhole, {});
    }
    rectifier_ = std::make_unique<Rectifier>(std::move(model));

    const std::string poses = options.ground_truth.empty() ? FindPoses(dir) : options.ground_truth;
    if (!poses.empty()) {
      ground_truth_ = ReadKittiPoses(poses, timestamps_);
      has_ground_truth_ = true;
    }
  }

  std::string format() const override { return "kitti"; }
};

}  // namespace

std::unique_ptr<Dataset> OpenKittiDataset(const std::string& dir, const DatasetOptions& options) {
  return std::make_unique<KittiDataset>(dir, options);
}

}  // namespace pldvo
