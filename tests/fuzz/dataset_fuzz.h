// The dataset-reader fuzz targets share this driver: a dataset folder in the scratch folder
// whose files all hold valid defaults except one, chosen by the input's first byte (modulo the
// number of files; '0', '1', ... select file 0, 1, ... for the usual small counts), which
// holds the rest of the input. The folder is opened through the public OpenDataset with the
// format fixed. Images are never decoded (Load is not called): they are fixtures only.
#ifndef PLDVO_TESTS_FUZZ_DATASET_FUZZ_H_
#define PLDVO_TESTS_FUZZ_DATASET_FUZZ_H_

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "core/dataset.h"
#include "tests/fuzz/fuzz_util.h"

namespace pldvo {
namespace fuzz {

struct FixtureFile {
  std::string relative_path;
  std::string default_content;
};

// Writes `count` gray PNGs of width x height named 000000.png, ... into `folder` (once).
inline void WriteImages(const std::string& folder, int count, int width, int height) {
  for (int i = 0; i < count; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/%06d.png", i);
    const std::string path = folder + name;
    if (std::filesystem::exists(path)) continue;
    std::filesystem::create_directories(folder);
    cv::Mat image(height, width, CV_8UC1, cv::Scalar(16 * i));
    if (!cv::imwrite(path, image)) Finding("cannot write fixture " + path);
  }
}

inline void CheckTrajectory(const Trajectory& trajectory) {
  for (size_t i = 0; i < trajectory.size(); ++i) {
    Require(std::isfinite(trajectory[i].timestamp), "non-finite ground-truth timestamp");
    Require(i == 0 || trajectory[i].timestamp > trajectory[i - 1].timestamp,
            "non-increasing ground-truth timestamps");
    Require(trajectory[i].world_from_cam.translation().allFinite() &&
                trajectory[i].world_from_cam.rotation().coeffs().allFinite(),
            "non-finite ground-truth pose");
  }
}

// The invariants of an opened dataset (core/dataset.h).
inline void CheckDataset(const Dataset& dataset, const std::string& format) {
  Require(dataset.format() == format, "format() is not the requested format");
  Require(dataset.size() > 0, "an empty sequence was accepted");
  for (int i = 0; i < dataset.size(); ++i) {
    const double t = dataset.timestamp(i);
    Require(std::isfinite(t), "non-finite frame timestamp");
    Require(i == 0 || t > dataset.timestamp(i - 1), "non-increasing frame timestamps");
  }
  const std::string problem = dataset.camera().Check();
  Require(problem.empty(), "invalid camera accepted: " + problem);
  Require(std::isfinite(dataset.camera().cx) && std::isfinite(dataset.camera().cy),
          "non-finite principal point accepted");
  if (dataset.ground_truth() != nullptr) CheckTrajectory(*dataset.ground_truth());
}

// True when a number token of the text lies in (1024, 32768]: an image side the readers accept
// (PinholeCamera::Check allows 32768) but whose undistortion maps take longer than the fuzzing
// timeout under the sanitizers (about 2 us a pixel). Targets whose files carry an image size
// skip such inputs; numbers above the bound (overflow, UB) are still fuzzed.
inline bool HasLargeImageSide(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  size_t begin = 0;
  while ((begin = text.find_first_of("0123456789", begin)) != std::string::npos) {
    const size_t end = text.find_first_not_of("0123456789.eE+-", begin);
    const double value = std::strtod(text.substr(begin, end - begin).c_str(), nullptr);
    if (value > 1024.0 && value <= 32768.0) return true;
    if (end == std::string::npos) break;
    begin = end;
  }
  return false;
}

// Runs one input: writes the files (file data[0] % files.size() from the input), opens the
// folder `dir` (created by the caller with its fixture images) as `format`.
inline int FuzzDatasetFolder(const uint8_t* data, size_t size, const std::string& dir,
                             const std::string& format, const std::vector<FixtureFile>& files,
                             bool skip_large_sizes = false, DatasetOptions options = {}) {
  if (size == 0) return 0;
  const size_t selected = data[0] % files.size();
  if (skip_large_sizes && HasLargeImageSide(data + 1, size - 1)) return 0;
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string path = dir + "/" + files[i].relative_path;
    if (i == selected) {
      WriteFile(path, data + 1, size - 1);
    } else {
      WriteFile(path, files[i].default_content);
    }
  }
  options.format = format;
  std::unique_ptr<Dataset> dataset;
  if (!RunParser([&] { dataset = OpenDataset(dir, options); }, dir)) return 0;
  Require(dataset != nullptr, "OpenDataset returned null without throwing");
  CheckDataset(*dataset, format);
  return 0;
}

}  // namespace fuzz
}  // namespace pldvo

#endif  // PLDVO_TESTS_FUZZ_DATASET_FUZZ_H_
