// Helpers shared by the dataset readers (core/*_dataset.cc): text tables with line numbers,
// number parsing that names file and line, image loading with size checks, timestamp
// association. Not a public interface: use core/dataset.h.
#ifndef PLDVO_CORE_DATASET_UTIL_H_
#define PLDVO_CORE_DATASET_UTIL_H_

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera_model.h"
#include "core/dataset.h"
#include "core/pinhole_camera.h"

namespace pldvo {
namespace dataset_util {

struct TableLine {
  int line_number = 0;  // 1-based line in the file
  std::vector<std::string> fields;
};

// Reads a text table: blank lines and lines starting with '#' are skipped; fields are split on
// whitespace, and also on commas when `commas` is true. Throws std::runtime_error when the file
// cannot be opened.
std::vector<TableLine> ReadTable(const std::string& path, bool commas = false);

// Throws std::runtime_error "path:line: message".
[[noreturn]] void FailAt(const std::string& path, int line_number, const std::string& message);

// A finite double / an integer occupying the whole field; errors name file and line.
double ParseDouble(const std::string& field, const std::string& path, int line_number);
int64_t ParseInt64(const std::string& field, const std::string& path, int line_number);

// Throws when fewer than `min_fields` (or more than `max_fields`, if >= 0) fields.
void RequireFields(const TableLine& line, int min_fields, int max_fields, const std::string& path,
                   const std::string& expected);

// Throws "path:line: timestamp t does not increase (previous p)" unless t > previous.
void RequireIncreasing(double previous, double t, const std::string& path, int line_number);

// EuRoC nanoseconds to seconds without losing the sub-microsecond digits in the division.
double NanosecondsToSeconds(int64_t ns);

// Reads an image as 8-bit gray (colour converted by the decoder, cv::IMREAD_GRAYSCALE). Throws
// std::runtime_error naming the file when it is missing or unreadable.
cv::Mat ReadGray8(const std::string& path);
// Throws std::runtime_error naming `path` when the image is not width x height.
void RequireSize(const cv::Mat& image, int width, int height, const std::string& path);

// The index of the value in an increasing vector closest to t, or -1 if none within max_diff.
int NearestIndex(const std::vector<double>& sorted, double t, double max_diff);

// Joins paths (std::filesystem semantics) / tests existence.
std::string JoinPath(const std::string& a, const std::string& b);
bool IsFile(const std::string& path);
bool IsDirectory(const std::string& path);
// Regular files of a folder with an image extension (.png .jpg .jpeg .pgm .ppm .bmp .tif
// .tiff, case-insensitive), sorted by name.
std::vector<std::string> ListImages(const std::string& dir);
bool HasImageExtension(const std::string& name);

// A camera model with the undistortion to its ideal pinhole (core/camera_model.h), applied to
// 8-bit gray images: converts to CV_32F 0..255 and remaps.
class Rectifier {
 public:
  explicit Rectifier(std::unique_ptr<CameraModel> model);
  const CameraModel& model() const { return *model_; }
  const PinholeCamera& input() const { return model_->intrinsics(); }
  const PinholeCamera& output() const { return undistorter_->output_camera(); }
  // `gray8` must be CV_8UC1 of the input size (checked by the caller, which knows the file).
  cv::Mat Rectify(const cv::Mat& gray8) const;
  // A CV_32F depth image of the input size, undistorted with nearest-neighbour sampling.
  cv::Mat RectifyDepth(const cv::Mat& depth) const { return undistorter_->UndistortNearest(depth); }

 private:
  std::unique_ptr<CameraModel> model_;
  std::unique_ptr<Undistorter> undistorter_;
};

// The plumbing of a reader whose frames are a list of timestamped image files under one
// Rectifier: the derived constructor fills timestamps_, paths_ (same length), rectifier_ and,
// when there is one, ground_truth_ with has_ground_truth_ = true. Load(i) reads paths_[i] as
// 8-bit gray, checks the rectifier's input size and rectifies it.
class ImageListDataset : public Dataset {
 public:
  int size() const override { return static_cast<int>(timestamps_.size()); }
  double timestamp(int i) const override { return timestamps_.at(i); }
  const PinholeCamera& camera() const override { return rectifier_->output(); }
  const Trajectory* ground_truth() const override {
    return has_ground_truth_ ? &ground_truth_ : nullptr;
  }
  Frame Load(int i) const override;

 protected:
  std::vector<double> timestamps_;
  std::vector<std::string> paths_;
  std::unique_ptr<Rectifier> rectifier_;
  Trajectory ground_truth_;
  bool has_ground_truth_ = false;
};

}  // namespace dataset_util
}  // namespace pldvo

#endif  // PLDVO_CORE_DATASET_UTIL_H_
