// libFuzzer target: the KITTI odometry reader (core/kitti_dataset.h through OpenDataset,
// format "kitti"): calib.txt, times.txt and the poses. Input: a selector byte ('0' calib.txt,
// '1' times.txt, '2' poses.txt), then that file; the others hold valid defaults. image_0/ holds
// three small fixture images, so times.txt must list three frames to get past the count check.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/fuzz/dataset_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  static const std::string dir = fuzz::ScratchDir() + "/kitti";
  static const std::vector<fuzz::FixtureFile> files = {
      {"calib.txt",
       "P0: 7.070912e+02 0.000000e+00 6.018873e+02 0.000000e+00 0.000000e+00 7.070912e+02 "
       "1.831104e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n"
       "P1: 7.070912e+02 0.000000e+00 6.018873e+02 -3.798145e+02 0.000000e+00 7.070912e+02 "
       "1.831104e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00\n"},
      {"times.txt", "0.000000e+00\n1.036224e-01\n2.072334e-01\n"},
      {"poses.txt",
       "1 0 0 0 0 1 0 0 0 0 1 0\n"
       "1 0 0 0 0 1 0 0 0 0 1 0.5\n"
       "0.9998 0 0.0199987 0 0 1 0 0 -0.0199987 0 0.9998 1.0\n"},
  };
  static const bool init = [] {
    fuzz::WriteImages(dir + "/image_0", 3, 40, 12);
    return true;
  }();
  (void)init;
  return fuzz::FuzzDatasetFolder(data, size, dir, "kitti", files);
}
