#include "core/camera_yaml.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <opencv2/core.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/config_io.h"

namespace pldvo {
namespace {

struct Preset {
  const char* name;
  const char* model;
  PinholeCamera intrinsics;
  std::vector<double> distortion;
};

// TUM RGB-D benchmark calibrations of the colour cameras (https://cvg.cit.tum.de/data/datasets/
// rgbd-dataset/file_formats): d0..d4 are OpenCV's k1 k2 p1 p2 k3. fr3 images are undistorted.
const std::vector<Preset>& Presets() {
  static const std::vector<Preset> presets = {
      {"tum_fr1",
       "radtan",
       {640, 480, 517.3, 516.5, 318.6, 255.3},
       {0.2624, -0.9531, -0.0054, 0.0026, 1.1633}},
      {"tum_fr2",
       "radtan",
       {640, 480, 520.9, 521.0, 325.1, 249.7},
       {0.2312, -0.7849, -0.0033, -0.0001, 0.9172}},
      {"tum_fr3", "pinhole", {640, 480, 535.4, 539.2, 320.1, 247.6}, {}},
  };
  return presets;
}

std::string NodeDescription(const cv::FileNode& node) {
  if (node.isMap()) return "a map";
  if (node.isSeq()) return "a list";
  if (node.isString()) return "the string '" + static_cast<std::string>(node) + "'";
  if (node.isInt()) return "an integer";
  if (node.isReal()) return "a number";
  return "no value";
}

class CameraYamlReader {
 public:
  CameraYamlReader(const std::string& path, const cv::FileNode& root) : path_(path), root_(root) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(path_ + ": key '" + key + "': " + what);
  }

  cv::FileNode Get(const std::string& key) const {
    const cv::FileNode node = root_[key];
    if (node.empty() && !node.isSeq()) {
      // An empty list "[]" is also empty(); only a missing key is an error here.
      bool present = false;
      for (cv::FileNodeIterator it = root_.begin(); it != root_.end(); ++it) {
        if ((*it).name() == key) present = true;
      }
      if (!present)
        Fail(key,
             "missing (camera.yaml needs model, width, height, fx, fy, cx, cy, "
             "distortion)");
    }
    return node;
  }

  std::string String(const std::string& key) const {
    const cv::FileNode node = Get(key);
    if (!node.isString()) Fail(key, "expected a string, got " + NodeDescription(node));
    return static_cast<std::string>(node);
  }

  int PositiveInt(const std::string& key) const {
    const cv::FileNode node = Get(key);
    if (!node.isInt()) Fail(key, "expected an integer, got " + NodeDescription(node));
    const int value = static_cast<int>(node);
    if (value <= 0) Fail(key, "must be positive, got " + std::to_string(value));
    return value;
  }

  double Number(const std::string& key) const {
    const cv::FileNode node = Get(key);
    if (!node.isInt() && !node.isReal()) {
      Fail(key, "expected a number, got " + NodeDescription(node));
    }
    const double value = static_cast<double>(node);
    if (!std::isfinite(value)) Fail(key, "must be finite");
    return value;
  }

  std::vector<double> Numbers(const std::string& key) const {
    const cv::FileNode node = Get(key);
    if (!node.isSeq()) {
      Fail(key, "expected a list of numbers like [0.1, -0.2], got " + NodeDescription(node));
    }
    std::vector<double> values;
    for (cv::FileNodeIterator it = node.begin(); it != node.end(); ++it) {
      const cv::FileNode item = *it;
      if (!item.isInt() && !item.isReal()) {
        Fail(key, "element " + std::to_string(values.size()) + " is " + NodeDescription(item) +
                      ", expected a number");
      }
      values.push_back(static_cast<double>(item));
    }
    return values;
  }

 private:
  std::string path_;
  cv::FileNode root_;
};

}  // namespace

std::unique_ptr<CameraModel> ReadCameraYaml(const std::string& path) {
  cv::FileStorage storage;
  OpenYamlForReading(path, &storage);
  const cv::FileNode root = storage.root();
  if (!root.isMap()) throw std::runtime_error(path + ": expected a map of camera keys");

  static const std::set<std::string> kKeys = {"model", "width", "height", "fx",
                                              "fy",    "cx",    "cy",     "distortion"};
  std::set<std::string> seen;
  for (cv::FileNodeIterator it = root.begin(); it != root.end(); ++it) {
    const std::string key = (*it).name();
    if (!kKeys.count(key)) {
      throw std::runtime_error(path + ": unknown key '" + key +
                               "' (valid: model, width, height, fx, fy, cx, cy, distortion)");
    }
    if (!seen.insert(key).second) throw std::runtime_error(path + ": duplicate key '" + key + "'");
  }

  const CameraYamlReader reader(path, root);
  const std::string model = reader.String("model");
  if (model != "pinhole" && model != "radtan" && model != "fov") {
    reader.Fail("model", "unknown model '" + model + "' (valid: pinhole, radtan, fov)");
  }
  PinholeCamera intrinsics;
  intrinsics.width = reader.PositiveInt("width");
  intrinsics.height = reader.PositiveInt("height");
  for (const char* key : {"fx", "fy"}) {
    const double focal = reader.Number(key);
    if (!(focal > 0.0))
      reader.Fail(key, "focal length must be positive, got " + std::to_string(focal));
    (key[1] == 'x' ? intrinsics.fx : intrinsics.fy) = focal;
  }
  intrinsics.cx = reader.Number("cx");
  intrinsics.cy = reader.Number("cy");
  const std::vector<double> distortion = reader.Numbers("distortion");
  const size_t expected = model == "radtan" ? 5 : model == "fov" ? 1 : 0;
  if (distortion.size() != expected) {
    reader.Fail("distortion", "model '" + model + "' takes " + std::to_string(expected) +
                                  " values (" +
                                  (model == "radtan" ? "k1, k2, p1, p2, k3"
                                   : model == "fov"  ? "w"
                                                     : "use []") +
                                  "), got " + std::to_string(distortion.size()));
  }
  try {
    return MakeCameraModel(model, intrinsics, distortion);
  } catch (const std::invalid_argument& error) {
    // The remaining checks are on the distortion values (e.g. fov w outside (0, pi)).
    reader.Fail("distortion", error.what());
  }
}

void WriteCameraYaml(const CameraModel& camera, const std::string& path) {
  std::ofstream file(path);
  if (!file) throw std::runtime_error(path + ": cannot open the file for writing");
  const PinholeCamera& k = camera.intrinsics();
  auto number = [](double value) {  // the shortest spelling that reads back exactly
    char buffer[64];
    for (int precision = 1; precision <= 17; ++precision) {
      std::snprintf(buffer, sizeof(buffer), "%.*g", precision, value);
      if (std::strtod(buffer, nullptr) == value) break;
    }
    // A real-looking spelling: cv::FileStorage reads "19444444444444444" as an int and wraps it.
    std::string text = buffer;
    if (text.find_first_of(".eE") == std::string::npos) text += ".0";
    return text;
  };
  file << "%YAML:1.0\n---\n"
       << "# pldvo camera calibration (docs/cameras.md). Pixel (0, 0) is the centre of the\n"
       << "# top-left pixel. distortion: radtan k1 k2 p1 p2 k3 | fov w | pinhole []\n"
       << "model: " << camera.model_name() << "\n"
       << "width: " << k.width << "\n"
       << "height: " << k.height << "\n"
       << "fx: " << number(k.fx) << "\n"
       << "fy: " << number(k.fy) << "\n"
       << "cx: " << number(k.cx) << "\n"
       << "cy: " << number(k.cy) << "\n"
       << "distortion: [";
  const std::vector<double> distortion = camera.distortion();
  for (size_t i = 0; i < distortion.size(); ++i) file << (i ? ", " : "") << number(distortion[i]);
  file << "]\n";
  file.close();
  if (!file) throw std::runtime_error(path + ": write failed");
}

std::unique_ptr<CameraModel> CameraPreset(const std::string& name) {
  for (const Preset& preset : Presets()) {
    if (name == preset.name) {
      return MakeCameraModel(preset.model, preset.intrinsics, preset.distortion);
    }
  }
  return nullptr;
}

std::vector<std::string> CameraPresetNames() {
  std::vector<std::string> names;
  for (const Preset& preset : Presets()) names.push_back(preset.name);
  return names;
}

std::unique_ptr<CameraModel> CameraFromPresetOrFile(const std::string& preset_or_path) {
  if (std::unique_ptr<CameraModel> preset = CameraPreset(preset_or_path)) return preset;
  if (!std::ifstream(preset_or_path)) {
    std::string names;
    for (const std::string& name : CameraPresetNames()) names += (names.empty() ? "" : ", ") + name;
    throw std::runtime_error("camera '" + preset_or_path + "' is neither a preset (" + names +
                             ") nor a readable camera.yaml");
  }
  return ReadCameraYaml(preset_or_path);
}

}  // namespace pldvo
