// libFuzzer target: camera.yaml (core/camera_yaml.h ReadCameraYaml). The input is the file.
// On accepted input: the model's parameters are valid, WriteCameraYaml reads back exactly, and
// the undistortion to the ideal pinhole (what every dataset reader builds next) can be set up.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "core/camera_model.h"
#include "core/camera_yaml.h"
#include "tests/fuzz/fuzz_util.h"

namespace pldvo {
namespace {

void CheckModel(const CameraModel& model) {
  const PinholeCamera& k = model.intrinsics();
  fuzz::Require(k.Check().empty(), "accepted intrinsics fail PinholeCamera::Check: " + k.Check());
  fuzz::Require(std::isfinite(k.cx) && std::isfinite(k.cy), "non-finite principal point");
  for (double d : model.distortion()) fuzz::Require(std::isfinite(d), "non-finite distortion");
}

}  // namespace
}  // namespace pldvo

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  const std::string path = fuzz::ScratchDir() + "/camera.yaml";
  const std::string copy_path = fuzz::ScratchDir() + "/camera_copy.yaml";
  fuzz::WriteFile(path, data, size);
  std::unique_ptr<CameraModel> model;
  if (!fuzz::RunParser([&] { model = ReadCameraYaml(path); }, path)) return 0;
  fuzz::Require(model != nullptr, "ReadCameraYaml returned null without throwing");
  CheckModel(*model);

  WriteCameraYaml(*model, copy_path);
  std::unique_ptr<CameraModel> copy;
  if (!fuzz::RunParser([&] { copy = ReadCameraYaml(copy_path); }, "")) {
    fuzz::Finding("WriteCameraYaml output is rejected by ReadCameraYaml");
  }
  const PinholeCamera& a = model->intrinsics();
  const PinholeCamera& b = copy->intrinsics();
  fuzz::Require(model->model_name() == copy->model_name() && a.width == b.width &&
                    a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx &&
                    a.cy == b.cy && model->distortion() == copy->distortion(),
                "WriteCameraYaml does not read back exactly");

  // The readers' next step. Large sizes are valid input and legitimately cost memory; bound the
  // image so one input stays within -rss_limit_mb.
  if (static_cast<int64_t>(a.width) * a.height <= 2048 * 2048) {
    fuzz::RunParser([&] { Undistorter undistorter(*model); }, "");
  }
  return 0;
}
