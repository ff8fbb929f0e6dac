#include "core/mono_vo_dataset.h"

#include <zip.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

#include "core/camera_yaml.h"
#include "core/dataset_util.h"
#include "core/statistics.h"

namespace pldvo {
namespace {

using namespace dataset_util;  // NOLINT(build/namespaces): the readers' own helpers

// Vignette values are clamped from below before dividing: the TUM monoVO vignettes fall to a few
// percent in the corners, and a zero would turn a corner pixel into infinity.
constexpr double kMinVignette = 1e-3;

// Images of the sequence: the files of images/, or the entries of images.zip, sorted by name.
class ImageSource {
 public:
  explicit ImageSource(const std::string& dir) {
    const std::string folder = JoinPath(dir, "images");
    const std::string zip_path = JoinPath(dir, "images.zip");
    if (IsDirectory(folder)) {
      names_ = ListImages(folder);
      if (names_.empty()) throw std::runtime_error(folder + ": no images in the folder");
      return;
    }
    if (!IsFile(zip_path)) {
      throw std::runtime_error(dir + ": tum_mono dataset needs images/ or images.zip");
    }
    int error_code = 0;
    archive_ = zip_open(zip_path.c_str(), ZIP_RDONLY, &error_code);
    if (archive_ == nullptr) {
      zip_error_t error;
      zip_error_init_with_code(&error, error_code);
      const std::string message = zip_error_strerror(&error);
      zip_error_fini(&error);
      throw std::runtime_error(zip_path + ": cannot open zip archive: " + message);
    }
    const zip_int64_t num_entries = zip_get_num_entries(archive_, 0);
    std::vector<std::pair<std::string, zip_uint64_t>> entries;
    for (zip_int64_t i = 0; i < num_entries; ++i) {
      const char* name = zip_get_name(archive_, static_cast<zip_uint64_t>(i), 0);
      if (name == nullptr) continue;
      const std::string entry_name = name;
      if (!entry_name.empty() && entry_name.back() != '/' && HasImageExtension(entry_name)) {
        entries.emplace_back(entry_name, static_cast<zip_uint64_t>(i));
      }
    }
    std::sort(entries.begin(), entries.end());
    for (const auto& [name, index] : entries) {
      names_.push_back(zip_path + ":" + name);
      zip_indices_.push_back(index);
    }
    if (names_.empty()) {
      zip_close(archive_);
      throw std::runtime_error(zip_path + ": no images in the archive");
    }
  }
  ~ImageSource() {
    if (archive_ != nullptr) zip_discard(archive_);
  }
  ImageSource(const ImageSource&) = delete;
  ImageSource& operator=(const ImageSource&) = delete;

  int size() const { return static_cast<int>(names_.size()); }
  const std::string& name(int i) const { return names_.at(i); }

  cv::Mat ReadGray8(int i) const {
    if (archive_ == nullptr) return dataset_util::ReadGray8(names_.at(i));
    std::vector<unsigned char> buffer;
    {
      // libzip archives are not safe for concurrent reads.
      std::lock_guard<std::mutex> lock(mutex_);
      zip_stat_t stat;
      zip_stat_init(&stat);
      if (zip_stat_index(archive_, zip_indices_.at(i), 0, &stat) != 0 ||
          !(stat.valid & ZIP_STAT_SIZE)) {
        throw std::runtime_error(names_[i] + ": cannot stat zip entry");
      }
      buffer.resize(stat.size);
      zip_file_t* file = zip_fopen_index(archive_, zip_indices_[i], 0);
      if (file == nullptr) throw std::runtime_error(names_[i] + ": cannot open zip entry");
      const zip_int64_t read = zip_fread(file, buffer.data(), stat.size);
      zip_fclose(file);
      if (read != static_cast<zip_int64_t>(stat.size)) {
        throw std::runtime_error(names_[i] + ": cannot read zip entry");
      }
    }
    cv::Mat image = cv::imdecode(buffer, cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw std::runtime_error(names_[i] + ": cannot decode image");
    return image;
  }

 private:
  std::vector<std::string> names_;  // file paths, or "images.zip:entry"
  zip_t* archive_ = nullptr;
  std::vector<zip_uint64_t> zip_indices_;
  mutable std::mutex mutex_;
};

bool IsNumber(const std::string& field) {
  char* end = nullptr;
  std::strtod(field.c_str(), &end);
  return end != field.c_str() && *end == '\0';
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// DSO's "relative" calibration (cx, cy < 1): fractions of the image size, with pixel (0, 0)
// covering [0, 1]^2; converted to our convention of pixel centres at integers.
PinholeCamera PixelIntrinsics(double fx, double fy, double cx, double cy, int width, int height) {
  PinholeCamera camera;
  camera.width = width;
  camera.height = height;
  if (cx < 1.0 && cy < 1.0) {
    camera.fx = fx * width;
    camera.fy = fy * height;
    camera.cx = cx * width - 0.5;
    camera.cy = cy * height - 0.5;
  } else {
    camera.fx = fx;
    camera.fy = fy;
    camera.cx = cx;
    camera.cy = cy;
  }
  return camera;
}

bool ProjectsInside(const CameraModel& model, double x, double y) {
  const Eigen::Vector2d pixel = model.Project(Eigen::Vector3d(x, y, 1.0));
  return pixel.allFinite() && model.intrinsics().IsInside(pixel, 0.0);
}

// The pinhole of size width x height whose image spans the normalised rectangle
// [min_x, max_x] x [min_y, max_y] (pixel 0 at min, pixel width-1 at max).
PinholeCamera PinholeSpanning(double min_x, double max_x, double min_y, double max_y, int width,
                              int height) {
  PinholeCamera camera;
  camera.width = width;
  camera.height = height;
  camera.fx = (width - 1) / (max_x - min_x);
  camera.fy = (height - 1) / (max_y - min_y);
  camera.cx = -min_x * camera.fx;
  camera.cy = -min_y * camera.fy;
  return camera;
}

// "crop" (as DSO): the largest axis-aligned rectangle of the undistorted image plane whose every
// point has a source pixel. Extents first grow along the centre lines until they leave the
// image, then each side shrinks by 0.5% while any point of it falls outside.
PinholeCamera CropCamera(const CameraModel& model, int width, int height, const std::string& path) {
  constexpr double kStep = 1e-3, kMaxExtent = 10.0;
  auto extent = [&](double dx, double dy) {
    double s = 0.0;
    while (s + kStep < kMaxExtent && ProjectsInside(model, (s + kStep) * dx, (s + kStep) * dy)) {
      s += kStep;
    }
    return s;
  };
  double min_x = -extent(-1, 0), max_x = extent(1, 0);
  double min_y = -extent(0, -1), max_y = extent(0, 1);
  constexpr int kSamples = 400;
  for (int iteration = 0; iteration < 5000; ++iteration) {
    bool left = false, right = false, top = false, bottom = false;
    for (int k = 0; k <= kSamples; ++k) {
      const double a = static_cast<double>(k) / kSamples;
      const double x = min_x + a * (max_x - min_x), y = min_y + a * (max_y - min_y);
      left = left || !ProjectsInside(model, min_x, y);
      right = right || !ProjectsInside(model, max_x, y);
      top = top || !ProjectsInside(model, x, min_y);
      bottom = bottom || !ProjectsInside(model, x, max_y);
    }
    if (!(left || right || top || bottom)) {
      if (max_x - min_x <= 0.0 || max_y - min_y <= 0.0) break;
      return PinholeSpanning(min_x, max_x, min_y, max_y, width, height);
    }
    if (left) min_x *= 0.995;
    if (right) max_x *= 0.995;
    if (top) min_y *= 0.995;
    if (bottom) max_y *= 0.995;
  }
  throw std::runtime_error(path + ": 'crop' found no valid undistorted rectangle");
}

// "full": the bounding box of the undistorted image border, so that every source pixel is kept
// (the corners of the output then have no source).
PinholeCamera FullCamera(const CameraModel& model, int width, int height) {
  const PinholeCamera& input = model.intrinsics();
  double min_x = 1e30, max_x = -1e30, min_y = 1e30, max_y = -1e30;
  auto add = [&](double u, double v) {
    const Eigen::Vector3d ray = model.Unproject(Eigen::Vector2d(u, v));
    min_x = std::min(min_x, ray.x());
    max_x = std::max(max_x, ray.x());
    min_y = std::min(min_y, ray.y());
    max_y = std::max(max_y, ray.y());
  };
  for (int u = 0; u < input.width; ++u) {
    add(u, 0);
    add(u, input.height - 1);
  }
  for (int v = 0; v < input.height; ++v) {
    add(0, v);
    add(input.width - 1, v);
  }
  return PinholeSpanning(min_x, max_x, min_y, max_y, width, height);
}

struct MonoCalibration {
  std::unique_ptr<CameraModel> model;
  PinholeCamera output;
};

// camera.txt (DSO's format):
//   line 1: [FOV|Pinhole|RadTan] fx fy cx cy dist...   5 numbers: FOV (w = 0: pinhole),
//           8 numbers: RadTan k1 k2 p1 p2; relative (cx, cy < 1) or in pixels
//   line 2: input width height
//   line 3: crop | full | none | fx fy cx cy 0   (optional; default none)
//   line 4: output width height                  (with line 3)
MonoCalibration ReadCameraTxt(const std::string& path) {
  const std::vector<TableLine> lines = ReadTable(path);
  if (lines.size() < 2) {
    throw std::runtime_error(path + ": expected at least 2 lines (intrinsics, image size)");
  }
  std::vector<std::string> first = lines[0].fields;
  const int first_line = lines[0].line_number;
  std::string model_name;
  if (!first.empty() && !IsNumber(first[0])) {
    model_name = Lower(first[0]);
    first.erase(first.begin());
  } else if (first.size() == 5) {
    model_name = "fov";
  } else if (first.size() == 8) {
    model_name = "radtan";
  }
  size_t expected = 0;
  if (model_name == "fov") expected = 5;
  if (model_name == "radtan") expected = 8;
  if (model_name == "pinhole") expected = first.size() == 5 ? 5 : 4;
  if (expected == 0) {
    FailAt(path, first_line,
           "unsupported camera model '" + (model_name.empty() ? std::string("?") : model_name) +
               "' (supported: FOV fx fy cx cy w | Pinhole fx fy cx cy | RadTan fx fy cx cy k1 "
               "k2 p1 p2)");
  }
  if (first.size() != expected) {
    FailAt(path, first_line,
           "camera model " + model_name + " needs " + std::to_string(expected) +
               " numbers, found " + std::to_string(first.size()));
  }
  std::vector<double> values;
  for (const std::string& field : first) values.push_back(ParseDouble(field, path, first_line));

  RequireFields(lines[1], 2, 2, path, "'width height'");
  const int in_width = static_cast<int>(ParseInt64(lines[1].fields[0], path, lines[1].line_number));
  const int in_height =
      static_cast<int>(ParseInt64(lines[1].fields[1], path, lines[1].line_number));
  if (in_width <= 0 || in_height <= 0)
    FailAt(path, lines[1].line_number, "non-positive image size");

  MonoCalibration calibration;
  const PinholeCamera intrinsics =
      PixelIntrinsics(values[0], values[1], values[2], values[3], in_width, in_height);
  std::vector<double> distortion;
  std::string model = "pinhole";
  if (model_name == "fov" && values[4] != 0.0) {
    model = "fov";
    distortion = {values[4]};
  } else if (model_name == "radtan") {
    model = "radtan";
    distortion = {values[4], values[5], values[6], values[7], 0.0};
  }
  try {
    calibration.model = MakeCameraModel(model, intrinsics, distortion);
  } catch (const std::exception& e) {
    FailAt(path, first_line, e.what());
  }

  if (lines.size() == 2) {
    calibration.output = intrinsics;
    return calibration;
  }
  if (lines.size() < 4)
    FailAt(path, lines[2].line_number, "output policy without output size line");
  const TableLine& size_line = lines[3];
  RequireFields(size_line, 2, 2, path, "'width height'");
  const int out_width =
      static_cast<int>(ParseInt64(size_line.fields[0], path, size_line.line_number));
  const int out_height =
      static_cast<int>(ParseInt64(size_line.fields[1], path, size_line.line_number));
  if (out_width <= 0 || out_height <= 0)
    FailAt(path, size_line.line_number, "non-positive image size");

  const TableLine& policy = lines[2];
  const std::string name = policy.fields.empty() ? "" : Lower(policy.fields[0]);
  if (name == "none") {
    if (out_width != in_width || out_height != in_height) {
      FailAt(path, policy.line_number, "'none' needs the output size equal to the input size");
    }
    calibration.output = intrinsics;
  } else if (name == "crop") {
    calibration.output = CropCamera(*calibration.model, out_width, out_height, path);
  } else if (name == "full") {
    calibration.output = FullCamera(*calibration.model, out_width, out_height);
  } else if (policy.fields.size() == 5 && IsNumber(policy.fields[0])) {
    double v[4];
    for (int i = 0; i < 4; ++i) v[i] = ParseDouble(policy.fields[i], path, policy.line_number);
    calibration.output = PixelIntrinsics(v[0], v[1], v[2], v[3], out_width, out_height);
  } else {
    FailAt(path, policy.line_number,
           "expected the output policy crop | full | none | 'fx fy cx cy 0'");
  }
  const std::string problem = calibration.output.Check();
  if (!problem.empty()) FailAt(path, policy.line_number, "output camera: " + problem);
  return calibration;
}

// pcalib.txt: the inverse response G^-1 as 256 increasing values for raw intensities 0..255;
// rescaled (as DSO does) so that G^-1(0) = 0 and G^-1(255) = 255.
std::vector<float> ReadInverseResponse(const std::string& path) {
  std::vector<double> values;
  for (const TableLine& line : ReadTable(path)) {
    for (const std::string& field : line.fields) {
      values.push_back(ParseDouble(field, path, line.line_number));
    }
  }
  if (values.size() != 256) {
    throw std::runtime_error(path + ": expected 256 inverse-response values, found " +
                             std::to_string(values.size()));
  }
  for (int i = 1; i < 256; ++i) {
    if (!(values[i] > values[i - 1])) {
      throw std::runtime_error(path + ": inverse response is not increasing at value " +
                               std::to_string(i));
    }
  }
  std::vector<float> inverse_response(256);
  for (int i = 0; i < 256; ++i) {
    inverse_response[i] =
        static_cast<float>(255.0 * (values[i] - values[0]) / (values[255] - values[0]));
  }
  return inverse_response;
}

// The median of the positive exposure times; 0 when none is positive (times.txt without
// exposures).
double MedianPositive(const std::vector<double>& exposures_ms) {
  std::vector<double> positive;
  std::copy_if(exposures_ms.begin(), exposures_ms.end(), std::back_inserter(positive),
               [](double t) { return t > 0.0; });
  return Median(std::move(positive));
}

// vignette.png (8 or 16 bit), normalised by its maximum; returns 1 / max(V, kMinVignette).
cv::Mat ReadInverseVignette(const std::string& path, int width, int height) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw std::runtime_error(path + ": cannot decode image");
  if (raw.channels() != 1) throw std::runtime_error(path + ": vignette must be single-channel");
  RequireSize(raw, width, height, path);
  cv::Mat vignette;
  raw.convertTo(vignette, CV_32F);
  double max_value = 0.0;
  cv::minMaxLoc(vignette, nullptr, &max_value);
  if (!(max_value > 0.0)) throw std::runtime_error(path + ": vignette is all zero");
  vignette /= max_value;
  cv::Mat inverse(vignette.size(), CV_32F);
  for (int y = 0; y < vignette.rows; ++y) {
    const float* in = vignette.ptr<float>(y);
    float* out = inverse.ptr<float>(y);
    for (int x = 0; x < vignette.cols; ++x) {
      out[x] = static_cast<float>(1.0 / std::max<double>(in[x], kMinVignette));
    }
  }
  return inverse;
}

class MonoVoDataset : public Dataset {
 public:
  MonoVoDataset(const std::string& dir, const DatasetOptions& options) : images_(dir) {
    ReadTimes(JoinPath(dir, "times.txt"));
    if (!options.camera.empty()) {
      // An override calibration: undistorted like every other reader's camera.yaml.
      model_ = CameraFromPresetOrFile(options.camera);
      override_undistorter_ = std::make_unique<Undistorter>(*model_);
      input_ = model_->intrinsics();
      output_ = override_undistorter_->output_camera();
    } else {
      const std::string camera_path = JoinPath(dir, "camera.txt");
      if (!IsFile(camera_path)) {
        throw std::runtime_error(camera_path + ": not found (tum_mono needs its calibration)");
      }
      MonoCalibration calibration = ReadCameraTxt(camera_path);
      model_ = std::move(calibration.model);
      input_ = model_->intrinsics();
      output_ = calibration.output;
      BuildRemap();
    }
    const std::string pcalib = JoinPath(dir, "pcalib.txt");
    if (IsFile(pcalib)) inverse_response_ = ReadInverseResponse(pcalib);
    // Exposure only scales linear intensities, i.e. after G^-1 (as DSO).
    if (options.normalize_exposure && !inverse_response_.empty()) {
      reference_exposure_ms_ = MedianPositive(exposures_ms_);
    }
    const std::string vignette = JoinPath(dir, "vignette.png");
    if (IsFile(vignette))
      inverse_vignette_ = ReadInverseVignette(vignette, input_.width, input_.height);
    if (!options.ground_truth.empty()) {
      ground_truth_ = ReadTrajectoryTum(options.ground_truth);
      has_ground_truth_ = true;
    }
  }

  std::string format() const override { return "tum_mono"; }
  int size() const override { return static_cast<int>(timestamps_.size()); }
  double timestamp(int i) const override { return timestamps_.at(i); }
  const PinholeCamera& camera() const override { return output_; }
  const Trajectory* ground_truth() const override {
    return has_ground_truth_ ? &ground_truth_ : nullptr;
  }

  Frame Load(int i) const override {
    Frame frame;
    frame.index = i;
    frame.timestamp = timestamps_.at(i);
    frame.exposure_ms = exposures_ms_[i];
    frame.path = images_.name(i);
    const cv::Mat raw = images_.ReadGray8(i);
    RequireSize(raw, input_.width, input_.height, frame.path);
    // I = (t_ref / t_i) G^-1(I_raw) / V, per pixel, before the geometric undistortion (V lives
    // on the raw image); the exposure factor is 1 without normalisation or a known exposure.
    const float exposure_scale = reference_exposure_ms_ > 0.0 && exposures_ms_[i] > 0.0
                                     ? static_cast<float>(reference_exposure_ms_ / exposures_ms_[i])
                                     : 1.0f;
    cv::Mat corrected(raw.size(), CV_32F);
    for (int y = 0; y < raw.rows; ++y) {
      const unsigned char* in = raw.ptr<unsigned char>(y);
      const float* inverse_vignette =
          inverse_vignette_.empty() ? nullptr : inverse_vignette_.ptr<float>(y);
      float* out = corrected.ptr<float>(y);
      for (int x = 0; x < raw.cols; ++x) {
        float value =
            inverse_response_.empty() ? static_cast<float>(in[x]) : inverse_response_[in[x]];
        if (inverse_vignette != nullptr) value *= inverse_vignette[x];
        out[x] = exposure_scale * value;
      }
    }
    if (override_undistorter_ != nullptr) {
      frame.image = override_undistorter_->Undistort(corrected);
    } else if (map_x_.empty()) {
      frame.image = corrected;
    } else {
      cv::remap(corrected, frame.image, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                cv::Scalar(0));
    }
    return frame;
  }

 private:
  void ReadTimes(const std::string& path) {
    if (!IsFile(path)) throw std::runtime_error(path + ": not found (tum_mono)");
    for (const TableLine& line : ReadTable(path)) {
      RequireFields(line, 2, 3, path, "'id timestamp [exposure_ms]'");
      const double t = ParseDouble(line.fields[1], path, line.line_number);
      if (!timestamps_.empty()) RequireIncreasing(timestamps_.back(), t, path, line.line_number);
      timestamps_.push_back(t);
      exposures_ms_.push_back(
          line.fields.size() == 3 ? ParseDouble(line.fields[2], path, line.line_number) : 0.0);
    }
    if (timestamps_.empty()) throw std::runtime_error(path + ": lists no frames");
    if (size() != images_.size()) {
      throw std::runtime_error(path + ": " + std::to_string(size()) + " timestamps for " +
                               std::to_string(images_.size()) + " images");
    }
  }

  // output pixel -> ray of the output pinhole -> distorted input pixel. Skipped for a pinhole
  // model whose output is its own intrinsics (the identity).
  void BuildRemap() {
    const bool identity = model_->model_name() == "pinhole" && output_.width == input_.width &&
                          output_.height == input_.height && output_.fx == input_.fx &&
                          output_.fy == input_.fy && output_.cx == input_.cx &&
                          output_.cy == input_.cy;
    if (identity) return;
    map_x_.create(output_.height, output_.width, CV_32F);
    map_y_.create(output_.height, output_.width, CV_32F);
    for (int v = 0; v < output_.height; ++v) {
      float* mx = map_x_.ptr<float>(v);
      float* my = map_y_.ptr<float>(v);
      for (int u = 0; u < output_.width; ++u) {
        const Eigen::Vector2d pixel = model_->Project(output_.Unproject(Eigen::Vector2d(u, v)));
        mx[u] = static_cast<float>(pixel.x());
        my[u] = static_cast<float>(pixel.y());
      }
    }
  }

  ImageSource images_;
  std::vector<double> timestamps_;
  std::vector<double> exposures_ms_;
  double reference_exposure_ms_ = 0.0;  // > 0: images are scaled by it / their exposure
  std::unique_ptr<CameraModel> model_;
  std::unique_ptr<Undistorter> override_undistorter_;
  PinholeCamera input_, output_;
  cv::Mat map_x_, map_y_;
  std::vector<float> inverse_response_;  // empty: identity
  cv::Mat inverse_vignette_;             // empty: no vignetting
  Trajectory ground_truth_;
  bool has_ground_truth_ = false;
};

}  // namespace

std::unique_ptr<Dataset> OpenMonoVoDataset(const std::string& dir, const DatasetOptions& options) {
  return std::make_unique<MonoVoDataset>(dir, options);
}

}  // namespace pldvo
