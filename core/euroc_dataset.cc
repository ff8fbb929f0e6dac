#include "core/euroc_dataset.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "core/camera_yaml.h"
#include "core/dataset_util.h"
#include "core/yaml_reader.h"

namespace pldvo {
namespace {

using namespace dataset_util;  // NOLINT(build/namespaces): the readers' own helpers

// The entry `key` of `map` (Require(Require(root, "T_BS"), "data") for T_BS.data); missing:
// "<path>: missing key 'T_BS.data'".
YamlNode Require(const YamlNode& map, const std::string& key) {
  std::optional<YamlNode> node = map.Find(key);
  if (!node) {
    const std::string dotted = map.key().empty() ? key : map.key() + "." + key;
    throw std::runtime_error(map.path() + ": missing key '" + dotted + "'");
  }
  return *node;
}

// A list of `count` finite numbers, e.g. T_BS.data: [r00, r01, r02, t0, ...] (row-major 4x4).
std::vector<double> NumberList(const YamlNode& node, size_t count) {
  if (!node.IsList()) {
    node.FailAtLine(node.key() + " must be a list of numbers like [1, 2], got " + node.Describe());
  }
  std::vector<double> numbers;
  for (const YamlNode& item : node.Items()) {
    double value = 0.0;
    if (!item.GetDouble(&value) || !std::isfinite(value)) {
      item.FailAtLine(node.key() + " element " + std::to_string(numbers.size()) + " is " +
                      item.Describe() + ", expected a finite number");
    }
    numbers.push_back(value);
  }
  if (numbers.size() != count) {
    node.FailAtLine(node.key() + " needs " + std::to_string(count) + " numbers, found " +
                    std::to_string(numbers.size()));
  }
  return numbers;
}

// A name-valued key such as camera_model (a string, not a number or a list).
std::string Name(const YamlNode& node) {
  std::string value;
  if (!node.GetString(&value))
    node.FailAtLine(node.key() + " must be a name, got " + node.Describe());
  return value;
}

struct EurocCamera {
  std::unique_ptr<CameraModel> model;
  SE3 body_from_cam;
};

// sensor.yaml is plain YAML (EuRoC's own files have no "%YAML" line; the OpenCV-style
// "%YAML:1.0" and "!!opencv-matrix" of other tools' copies read as well). Keys other than the
// ones below (sensor_type, comment, rate_hz, T_BS.rows, ...) are ignored.
EurocCamera ReadEurocCamera(const std::string& path) {
  const YamlNode root = YamlNode::ReadFile(path);
  if (!root.IsMap() && !root.IsNull()) {
    root.FailAtLine("expected a map of sensor keys, got " + root.Describe());
  }
  EurocCamera camera;
  const YamlNode t_bs_node = Require(Require(root, "T_BS"), "data");
  const std::vector<double> t_bs = NumberList(t_bs_node, 16);
  Eigen::Matrix3d rotation;
  rotation << t_bs[0], t_bs[1], t_bs[2], t_bs[4], t_bs[5], t_bs[6], t_bs[8], t_bs[9], t_bs[10];
  if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-4 ||
      rotation.determinant() < 0.0) {
    t_bs_node.FailAtLine("T_BS rotation is not orthonormal");
  }
  camera.body_from_cam = SE3(rotation, Eigen::Vector3d(t_bs[3], t_bs[7], t_bs[11]));

  const YamlNode resolution_node = Require(root, "resolution");
  const std::vector<double> resolution = NumberList(resolution_node, 2);
  const YamlNode intrinsics_node = Require(root, "intrinsics");
  const std::vector<double> intrinsics = NumberList(intrinsics_node, 4);
  const YamlNode projection = Require(root, "camera_model");
  if (Name(projection) != "pinhole") {
    projection.FailAtLine("unsupported camera_model '" + Name(projection) + "'");
  }
  for (double side : resolution) {  // casting a double beyond int's range is undefined
    if (!(side >= 1.0 && side <= std::numeric_limits<int>::max()) || side != std::floor(side)) {
      resolution_node.FailAtLine("resolution must be two positive integers");
    }
  }
  PinholeCamera pinhole;
  pinhole.width = static_cast<int>(resolution[0]);
  pinhole.height = static_cast<int>(resolution[1]);
  pinhole.fx = intrinsics[0];
  pinhole.fy = intrinsics[1];
  pinhole.cx = intrinsics[2];
  pinhole.cy = intrinsics[3];
  const YamlNode distortion_node = Require(root, "distortion_model");
  const std::string distortion_model = Name(distortion_node);
  std::string model;
  std::vector<double> distortion;
  if (distortion_model == "radial-tangential" || distortion_model == "radtan") {
    model = "radtan";
    distortion = NumberList(Require(root, "distortion_coefficients"), 4);
    distortion.push_back(0.0);  // k3
  } else if (distortion_model == "none") {
    model = "pinhole";
  } else {
    distortion_node.FailAtLine("unsupported distortion_model '" + distortion_model +
                               "' (supported: radial-tangential, none)");
  }
  try {
    camera.model = MakeCameraModel(model, pinhole, distortion);
  } catch (const std::exception& e) {
    intrinsics_node.FailAtLine(e.what());
  }
  return camera;
}

// state_groundtruth_estimate0/data.csv: timestamp [ns], p_RS_R (3), q_RS (w x y z), ...; the
// body (IMU) pose in the world, moved to the camera: world_from_cam = world_from_body * T_BS.
Trajectory ReadEurocGroundTruth(const std::string& path, const SE3& body_from_cam) {
  Trajectory trajectory;
  for (const TableLine& line : ReadTable(path, /*commas=*/true)) {
    RequireFields(line, 8, -1, path, "at least 8 fields 'timestamp[ns] px py pz qw qx qy qz'");
    StampedPose pose;
    pose.timestamp = NanosecondsToSeconds(ParseInt64(line.fields[0], path, line.line_number));
    if (!trajectory.empty()) {
      RequireIncreasing(trajectory.back().timestamp, pose.timestamp, path, line.line_number);
    }
    double v[7];
    for (int i = 0; i < 7; ++i) v[i] = ParseDouble(line.fields[i + 1], path, line.line_number);
    const Eigen::Quaterniond rotation(v[3], v[4], v[5], v[6]);
    if (std::abs(rotation.norm() - 1.0) > 1e-3) {
      FailAt(path, line.line_number, "quaternion (qw qx qy qz) is not of unit norm");
    }
    const SE3 world_from_body(rotation, Eigen::Vector3d(v[0], v[1], v[2]));
    pose.world_from_cam = world_from_body * body_from_cam;
    trajectory.push_back(pose);
  }
  return trajectory;
}

class EurocDataset : public ImageListDataset {
 public:
  EurocDataset(const std::string& dir, const DatasetOptions& options) {
    const std::string mav0 = IsDirectory(JoinPath(dir, "mav0")) ? JoinPath(dir, "mav0") : dir;
    const std::string cam0 = JoinPath(mav0, "cam0");
    const std::string list = JoinPath(cam0, "data.csv");
    if (!IsFile(list)) throw std::runtime_error(list + ": not found (euroc dataset)");
    const std::string sensor = JoinPath(cam0, "sensor.yaml");
    SE3 body_from_cam;
    std::unique_ptr<CameraModel> model;
    if (!options.camera.empty()) {
      model = CameraFromPresetOrFile(options.camera);
      if (IsFile(sensor)) body_from_cam = ReadEurocCamera(sensor).body_from_cam;
    } else {
      if (!IsFile(sensor)) throw std::runtime_error(sensor + ": not found (euroc calibration)");
      EurocCamera camera = ReadEurocCamera(sensor);
      model = std::move(camera.model);
      body_from_cam = camera.body_from_cam;
    }
    rectifier_ = std::make_unique<Rectifier>(std::move(model));

    for (const TableLine& line : ReadTable(list, /*commas=*/true)) {
      RequireFields(line, 2, 2, list, "2 fields 'timestamp[ns],filename'");
      const double t = NanosecondsToSeconds(ParseInt64(line.fields[0], list, line.line_number));
      if (!timestamps_.empty()) RequireIncreasing(timestamps_.back(), t, list, line.line_number);
      timestamps_.push_back(t);
      paths_.push_back(JoinPath(JoinPath(cam0, "data"), line.fields[1]));
    }
    if (timestamps_.empty()) throw std::runtime_error(list + ": lists no images");

    const std::string gt = JoinPath(mav0, "state_groundtruth_estimate0/data.csv");
    if (!options.ground_truth.empty()) {
      ground_truth_ = ReadTrajectoryTum(options.ground_truth);
      has_ground_truth_ = true;
    } else if (IsFile(gt)) {
      ground_truth_ = ReadEurocGroundTruth(gt, body_from_cam);
      has_ground_truth_ = true;
    }
  }

  std::string format() const override { return "euroc"; }
};

}  // namespace

std::unique_ptr<Dataset> OpenEurocDataset(const std::string& dir, const DatasetOptions& options) {
  return std::make_unique<EurocDataset>(dir, options);
}

}  // namespace pldvo
