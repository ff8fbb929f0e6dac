#include "core/tum_dataset.h"

#include <glog/logging.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "core/camera_yaml.h"
#include "core/dataset_util.h"

namespace pldvo {
namespace {

using namespace dataset_util;  // NOLINT(build/namespaces): the readers' own helpers

// TUM's associate.py default: an rgb and a depth image further apart are not a pair.
constexpr double kMaxAssociationDiff = 0.02;

struct Entry {
  double timestamp = 0.0;
  std::string path;
};

// "timestamp filename" lines; filenames relative to the folder.
std::vector<Entry> ReadImageList(const std::string& dir, const std::string& list_path) {
  std::vector<Entry> entries;
  for (const TableLine& line : ReadTable(list_path)) {
    RequireFields(line, 2, 2, list_path, "2 fields 'timestamp filename'");
    Entry entry;
    entry.timestamp = ParseDouble(line.fields[0], list_path, line.line_number);
    if (!entries.empty()) {
      RequireIncreasing(entries.back().timestamp, entry.timestamp, list_path, line.line_number);
    }
    entry.path = JoinPath(dir, line.fields[1]);
    entries.push_back(entry);
  }
  return entries;
}

// The camera: DatasetOptions::camera, else the folder's camera.yaml, else the TUM preset named
// by a folder called rgbd_dataset_freiburgN_*.
std::unique_ptr<CameraModel> TumCamera(const std::string& dir, const DatasetOptions& options) {
  if (!options.camera.empty()) return CameraFromPresetOrFile(options.camera);
  const std::string yaml = JoinPath(dir, "camera.yaml");
  if (IsFile(yaml)) return ReadCameraYaml(yaml);
  std::filesystem::path folder = std::filesystem::absolute(dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();
  const std::string name = folder.filename().string();
  for (const char* n : {"1", "2", "3"}) {
    if (name.find(std::string("freiburg") + n) != std::string::npos) {
      LOG(INFO) << dir << ": no camera.yaml; using preset tum_fr" << n << " (folder name)";
      return CameraFromPresetOrFile(std::string("tum_fr") + n);
    }
  }
  throw std::runtime_error(dir +
                           ": tum dataset without camera.yaml; give a camera (preset tum_fr1 | "
                           "tum_fr2 | tum_fr3 or a camera.yaml path)");
}

class TumDataset : public Dataset {
 public:
  TumDataset(const std::string& dir, const DatasetOptions& options)
      : rectifier_(TumCamera(dir, options)) {
    const std::string rgb_list = JoinPath(dir, "rgb.txt");
    if (!IsFile(rgb_list)) throw std::runtime_error(rgb_list + ": not found (tum dataset)");
    frames_ = ReadImageList(dir, rgb_list);
    if (frames_.empty()) throw std::runtime_error(rgb_list + ": lists no images");

    const std::string depth_list = JoinPath(dir, "depth.txt");
    depth_paths_.assign(frames_.size(), "");
    if (IsFile(depth_list)) {
      const std::vector<Entry> depths = ReadImageList(dir, depth_list);
      std::vector<double> depth_times;
      for (const Entry& depth : depths) depth_times.push_back(depth.timestamp);
      for (size_t i = 0; i < frames_.size(); ++i) {
        const int k = NearestIndex(depth_times, frames_[i].timestamp, kMaxAssociationDiff);
        if (k >= 0) depth_paths_[i] = depths[k].path;
      }
    }

    const std::string gt_path =
        options.ground_truth.empty() ? JoinPath(dir, "groundtruth.txt") : options.ground_truth;
    if (!options.ground_truth.empty() || IsFile(gt_path)) {
      ground_truth_ = ReadTrajectoryTum(gt_path);
      has_ground_truth_ = true;
    }
  }

  std::string format() const override { return "tum"; }
  int size() const override { return static_cast<int>(frames_.size()); }
  double timestamp(int i) const override { return frames_.at(i).timestamp; }
  const PinholeCamera& camera() const override { return rectifier_.output(); }
  const Trajectory* ground_truth() const override {
    return has_ground_truth_ ? &ground_truth_ : nullptr;
  }

  Frame Load(int i) const override {
    const Entry& entry = frames_.at(i);
    const cv::Mat raw = ReadGray8(entry.path);
    RequireSize(raw, rectifier_.input().width, rectifier_.input().height, entry.path);
    Frame frame;
    frame.index = i;
    frame.timestamp = entry.timestamp;
    frame.path = entry.path;
    frame.depth_path = depth_paths_[i];
    frame.image = rectifier_.Rectify(raw);
    return frame;
  }

  // TUM depth PNGs: 16-bit, metres x 5000 (docs/datasets.md).
  cv::Mat LoadDepth(int i) const override {
    const std::string& path = depth_paths_.at(i);
    if (path.empty()) return cv::Mat();
    const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
    if (raw.empty()) throw std::runtime_error(path + ": cannot read the depth image");
    if (raw.type() != CV_16UC1) throw std::runtime_error(path + ": not a 16-bit depth PNG");
    RequireSize(raw, rectifier_.input().width, rectifier_.input().height, path);
    cv::Mat depth;
    raw.convertTo(depth, CV_32F, 1.0 / 5000.0);
    return rectifier_.RectifyDepth(depth);
  }

 private:
  Rectifier rectifier_;
  std::vector<Entry> frames_;
  std::vector<std::string> depth_paths_;
  Trajectory ground_truth_;
  bool has_ground_truth_ = false;
};

}  // namespace

std::unique_ptr<Dataset> OpenTumDataset(const std::string& dir, const DatasetOptions& options) {
  return std::make_unique<TumDataset>(dir, options);
}

}  // namespace pldvo
