#include "core/dataset.h"

#include <algorithm>
#include <stdexcept>

#include "core/dataset_util.h"
#include "core/euroc_dataset.h"
#include "core/kitti_dataset.h"
#include "core/mono_vo_dataset.h"
#include "core/tum_dataset.h"

namespace pldvo {

using dataset_util::IsDirectory;
using dataset_util::IsFile;
using dataset_util::JoinPath;

const std::vector<std::string>& DatasetFormats() {
  static const std::vector<std::string> kFormats = {"tum", "tum_mono", "euroc", "kitti"};
  return kFormats;
}

std::string DatasetOptions::Check() const {
  if (format == "auto") return "";
  const auto& formats = DatasetFormats();
  if (std::find(formats.begin(), formats.end(), format) != formats.end()) return "";
  std::string known = "auto";
  for (const std::string& name : formats) known += " | " + name;
  return "format: unknown dataset format '" + format + "' (known: " + known + ")";
}

std::string DetectDatasetFormat(const std::string& dir) {
  if (!IsDirectory(dir)) throw std::runtime_error(dir + ": dataset folder not found");
  auto file = [&](const char* name) { return IsFile(JoinPath(dir, name)); };
  auto folder = [&](const char* name) { return IsDirectory(JoinPath(dir, name)); };
  if (file("mav0/cam0/data.csv") || file("cam0/data.csv")) return "euroc";
  if (file("calib.txt") && file("times.txt") && folder("image_0")) return "kitti";
  if (file("times.txt") && (folder("images") || file("images.zip"))) return "tum_mono";
  if (file("rgb.txt")) return "tum";
  throw std::runtime_error(
      dir +
      ": no known dataset layout; looked for mav0/cam0/data.csv or cam0/data.csv (euroc), "
      "calib.txt + times.txt + image_0/ (kitti), times.txt + images/ or images.zip (tum_mono), "
      "rgb.txt (tum)");
}

std::unique_ptr<Dataset> OpenDataset(const std::string& dir, const DatasetOptions& options) {
  const std::string problem = options.Check();
  if (!problem.empty()) throw std::invalid_argument("dataset options: " + problem);
  if (!IsDirectory(dir)) throw std::runtime_error(dir + ": dataset folder not found");
  const std::string format = options.format == "auto" ? DetectDatasetFormat(dir) : options.format;
  if (format == "tum") return OpenTumDataset(dir, options);
  if (format == "tum_mono") return OpenMonoVoDataset(dir, options);
  if (format == "euroc") return OpenEurocDataset(dir, options);
  return OpenKittiDataset(dir, options);
}

}  // namespace pldvo
