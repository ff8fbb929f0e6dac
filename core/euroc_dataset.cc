#include "core/euroc_dataset.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "core/camera_yaml.h"
#include "core/dataset_util.h"

namespace pldvo {
namespace {

using namespace dataset_util;  // NOLINT(build/namespaces): the readers' own helpers

// The few keys of an EuRoC sensor.yaml (not cv::FileStorage YAML: no %YAML header, T_BS as a
// plain map): top-level `key: value` pairs, bracketed lists possibly spanning lines, and the
// `data:` list nested under `T_BS:`. Values keep the line they start on for error messages.
struct YamlValue {
  std::string text;  // scalar, or the inside of [...]
  int line_number = 0;
};

std::map<std::string, YamlValue> ReadSensorYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::map<std::string, YamlValue> values;
  std::string line, parent, open_key;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (!open_key.empty()) {  // continuing a [...] list
      const size_t close = line.find(']');
      values[open_key].text += " " + line.substr(0, close);
      if (close != std::string::npos) open_key.clear();
      continue;
    }
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const size_t indent = line.find_first_not_of(" \t");
    std::string key = line.substr(indent, colon - indent);
    while (!key.empty() && (key.back() == ' ' || key.back() == '\t')) key.pop_back();
    if (indent == 0) parent = key;
    const std::string full_key = indent == 0 ? key : parent + "." + key;
    std::string value = line.substr(colon + 1);
    const size_t open = value.find('[');
    YamlValue entry;
    entry.line_number = line_number;
    if (open != std::string::npos) {
      const size_t close = value.find(']', open);
      entry.text =
          value.substr(open + 1, close == std::string::npos ? std::string::npos : close - open - 1);
      if (close == std::string::npos) open_key = full_key;
    } else {
      const size_t first = value.find_first_not_of(" \t\r");
      const size_t last = value.find_last_not_of(" \t\r");
      entry.text = first == std::string::npos ? "" : value.substr(first, last - first + 1);
    }
    values[full_key] = entry;
  }
  return values;
}

const YamlValue& Require(const std::map<std::string, YamlValue>& values, const std::string& key,
                         const std::string& path) {
  const auto it = values.find(key);
  if (it == values.end()) throw std::runtime_error(path + ": missing key '" + key + "'");
  return it->second;
}

std::vector<double> NumberList(const YamlValue& value, const std::string& path, size_t count,
                               const std::string& key) {
  std::string text = value.text;
  for (char& c : text) {
    if (c == ',') c = ' ';
  }
  std::istringstream fields(text);
  std::vector<double> numbers;
  std::string field;
  while (fields >> field) numbers.push_back(ParseDouble(field, path, value.line_number));
  if (numbers.size() != count) {
    FailAt(path, value.line_number,
           key + " needs " + std::to_string(count) + " numbers, found " +
               std::to_string(numbers.size()));
  }
  return numbers;
}

struct EurocCamera {
  std::unique_ptr<CameraModel> model;
  SE3 body_from_cam;
};

EurocCamera ReadEurocCamera(const std::string& path) {
  const auto values = ReadSensorYaml(path);
  EurocCamera camera;
  const std::vector<double> t_bs =
      NumberList(Require(values, "T_BS.data", path), path, 16, "T_BS.data");
  Eigen::Matrix3d rotation;
  rotation << t_bs[0], t_bs[1], t_bs[2], t_bs[4], t_bs[5], t_bs[6], t_bs[8], t_bs[9], t_bs[10];
  const int t_line = Require(values, "T_BS.data", path).line_number;
  if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-4 ||
      rotation.determinant() < 0.0) {
    FailAt(path, t_line, "T_BS rotation is not orthonormal");
  }
  camera.body_from_cam = SE3(rotation, Eigen::Vector3d(t_bs[3], t_bs[7], t_bs[11]));

  const std::vector<double> resolution =
      NumberList(Require(values, "resolution", path), path, 2, "resolution");
  const std::vector<double> intrinsics =
      NumberList(Require(values, "intrinsics", path), path, 4, "intrinsics");
  const YamlValue& projection = Require(values, "camera_model", path);
  if (projection.text != "pinhole") {
    FailAt(path, projection.line_number, "unsupported camera_model '" + projection.text + "'");
  }
  for (double side : resolution) {  // casting a double beyond int's range is undefined
    if (!(side >= 1.0 && side <= std::numeric_limits<int>::max()) || side != std::floor(side)) {
      FailAt(path, Require(values, "resolution", path).line_number,
             "resolution must be two positive integers");
    }
  }
  PinholeCamera pinhole;
  pinhole.width = static_cast<int>(resolution[0]);
  pinhole.height = static_cast<int>(resolution[1]);
  pinhole.fx = intrinsics[0];
  pinhole.fy = intrinsics[1];
  pinhole.cx = intrinsics[2];
  pinhole.cy = intrinsics[3];
  const YamlValue& distortion_model = Require(values, "distortion_model", path);
  std::string model;
  std::vector<double> distortion;
  if (distortion_model.text == "radial-tangential" || distortion_model.text == "radtan") {
    model = "radtan";
    distortion = NumberList(Require(values, "distortion_coefficients", path), path, 4,
                            "distortion_coefficients");
    distortion.push_back(0.0);  // k3
  } else if (distortion_model.text == "none") {
    model = "pinhole";
  } else {
    FailAt(path, distortion_model.line_number,
           "unsupported distortion_model '" + distortion_model.text +
               "' (supported: radial-tangential, none)");
  }
  try {
    camera.model = MakeCameraModel(model, pinhole, distortion);
  } catch (const std::exception& e) {
    FailAt(path, Require(values, "intrinsics", path).line_number, e.what());
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
