// libFuzzer target: the TUM monoVO reader (core/mono_vo_dataset.h through OpenDataset, format
// "tum_mono"): times.txt, camera.txt and pcalib.txt. Input: a selector byte ('0' times.txt,
// '1' camera.txt, '2' pcalib.txt), then that file; the others hold valid defaults. images/
// holds three small fixture images, so times.txt must list three frames to get past the count
// check.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/fuzz/dataset_fuzz.h"

namespace {

std::string LinearResponse() {
  std::string text;
  for (int i = 0; i < 256; ++i) text += std::to_string(i) + (i % 16 == 15 ? "\n" : " ");
  return text;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pldvo;  // NOLINT(build/namespaces)
  static const std::string dir = fuzz::ScratchDir() + "/mono";
  static const std::vector<fuzz::FixtureFile> files = {
      {"times.txt", "00000 1.0 20.0\n00001 1.05 20.5\n00002 1.1 21.0\n"},
      {"camera.txt", "0.535 0.669 0.493 0.500 0.897\n40 30\n"},
      {"pcalib.txt", LinearResponse()},
  };
  static const bool init = [] {
    fuzz::WriteImages(dir + "/images", 3, 40, 30);
    return true;
  }();
  (void)init;
  return fuzz::FuzzDatasetFolder(data, size, dir, "tum_mono", files, /*skip_large_sizes=*/true);
}
