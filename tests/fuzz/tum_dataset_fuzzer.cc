// libFuzzer target: the TUM RGB-D reader (core/tum_dataset.h through OpenDataset, format
// "tum"): rgb.txt, depth.txt and groundtruth.txt. Input: a selector byte ('0' rgb.txt,
// '1' depth.txt, '2' groundtruth.txt), then that file; the others hold valid defaults.
// camera.yaml has its own target (camera_yaml_fuzzer) and is fixed here to a small camera.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/fuzz/dataset_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  static const std::string dir = fuzz::ScratchDir() + "/tum";
  static const std::vector<fuzz::FixtureFile> files = {
      {"rgb.txt", "# timestamp filename\n1.0 rgb/000000.png\n1.1 rgb/000001.png\n"},
      {"depth.txt", "1.01 depth/000000.png\n1.09 depth/000001.png\n"},
      {"groundtruth.txt", "1.0 0 0 0 0 0 0 1\n1.05 0.1 0 0 0 0 0.0499792 0.9987503\n"},
      {"camera.yaml",
       "model: radtan\nwidth: 32\nheight: 24\nfx: 30\nfy: 30\ncx: 15.5\ncy: 11.5\n"
       "distortion: [0.1, -0.05, 0.001, 0.001, 0.0]\n"},
  };
  // camera.yaml is never selected: selectors cover the first three files only.
  static const std::vector<fuzz::FixtureFile> fuzzed(files.begin(), files.begin() + 3);
  static const bool init = [] {
    fuzz::WriteFile(dir + "/camera.yaml", files[3].default_content);
    fuzz::WriteImages(dir + "/rgb", 2, 32, 24);
    return true;
  }();
  (void)init;
  return fuzz::FuzzDatasetFolder(data, size, dir, "tum", fuzzed);
}
