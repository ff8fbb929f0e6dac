// camera.yaml: the calibration file (read by core/yaml_reader.h; OpenCV's FileStorage reads it
// too):
//   %YAML:1.0
//   ---
//   model: pinhole        # pinhole | radtan | fov
//   width: 640
//   height: 480
//   fx: 525.0
//   fy: 525.0
//   cx: 319.5
//   cy: 239.5
//   distortion: []        # k1 k2 p1 p2 k3 for radtan, w for fov, empty for pinhole
// Every key is required (distortion: [] for pinhole); an unknown key is an error, as in the
// config files. The "%YAML:1.0" first line may be omitted. Numbers may be written as integers.
// Built-in presets tum_fr1, tum_fr2, tum_fr3 carry the TUM-published calibrations (640x480).
#ifndef PLDVO_CORE_CAMERA_YAML_H_
#define PLDVO_CORE_CAMERA_YAML_H_

#include <memory>
#include <string>
#include <vector>

#include "core/camera_model.h"

namespace pldvo {

// Reads a camera.yaml; throws std::runtime_error naming the file, the line and the missing or bad
// key.
std::unique_ptr<CameraModel> ReadCameraYaml(const std::string& path);
// Writes a camera.yaml that ReadCameraYaml reads back exactly.
void WriteCameraYaml(const CameraModel& camera, const std::string& path);
// The built-in preset of that name, or nullptr when there is none.
std::unique_ptr<CameraModel> CameraPreset(const std::string& name);
// The preset names: tum_fr1, tum_fr2, tum_fr3.
std::vector<std::string> CameraPresetNames();
// A preset name (tum_fr1 | tum_fr2 | tum_fr3) or a path to a camera.yaml; throws
// std::runtime_error listing the presets when it is neither.
std::unique_ptr<CameraModel> CameraFromPresetOrFile(const std::string& preset_or_path);

}  // namespace pldvo

#endif  // PLDVO_CORE_CAMERA_YAML_H_
