#include "core/camera_yaml.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <set>
#include <stdexcept>

#include "core/yaml_reader.h"

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

// Reads the keys of a camera.yaml's top-level map; errors name the file, the line and the key.
class CameraYamlReader {
 public:
  explicit CameraYamlReader(const YamlNode& root) : root_(root) {}

  YamlNode Get(const std::string& key) const {
    std::optional<YamlNode> node = root_.Find(key);
    if (!node) {
      throw std::runtime_error(root_.path() + ": key '" + key +
                               "': missing (camera.yaml needs model, width, height, fx, fy, cx, "
                               "cy, distortion)");
    }
    return *node;
  }

  std::string String(const std::string& key) const {
    const YamlNode node = Get(key);
    std::string value;
    if (!node.GetString(&value)) node.Fail("expected a string, got " + node.Describe());
    return value;
  }

  int PositiveInt(const std::string& key) const {
    const YamlNode node = Get(key);
    int value = 0;
    if (!node.GetInt(&value)) node.Fail("expected an integer, got " + node.Describe());
    if (value <= 0) node.Fail("must be positive, got " + std::to_string(value));
    return value;
  }

  double Number(const std::string& key) const {
    const YamlNode node = Get(key);
    double value = 0.0;
    if (!node.GetDouble(&value)) node.Fail("expected a number, got " + node.Describe());
    if (!std::isfinite(value)) node.Fail("must be finite");
    return value;
  }

  std::vector<double> Numbers(const std::string& key) const {
    const YamlNode node = Get(key);
    if (!node.IsList()) {
      node.Fail("expected a list of numbers like [0.1, -0.2], got " + node.Describe());
    }
    std::vector<double> values;
    for (const YamlNode& item : node.Items()) {
      double value = 0.0;
      if (!item.GetDouble(&value)) {
        item.Fail("element " + std::to_string(values.size()) + " is " + item.Describe() +
                  ", expected a number");
      }
      values.push_back(value);
    }
    return values;
  }

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    Get(key).Fail(what);
  }

 private:
  YamlNode root_;
};

}  // namespace

std::unique_ptr<CameraModel> ReadCameraYaml(const std::string& path) {
  const YamlNode root = YamlNode::ReadFile(path);
  if (!root.IsMap()) root.FailAtLine("expected a map of camera keys, got " + root.Describe());
  static const std::set<std::string> kKeys = {"model", "width", "height", "fx",
                                              "fy",    "cx",    "cy",     "distortion"};
  for (const YamlNode& entry : root.Entries()) {  // unique (YamlNode::ReadFile checks)
    if (!kKeys.count(entry.name())) {
      entry.FailAtLine("unknown key '" + entry.name() +
                       "' (valid: model, width, height, fx, fy, cx, cy, distortion)");
    }
  }

  const CameraYamlReader reader(root);
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
    // A real-looking spelling: OpenCV's reader takes "19444444444444444" for an int and wraps it.
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
