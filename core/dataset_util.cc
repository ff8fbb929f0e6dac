#include "core/dataset_util.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

namespace pldvo {
namespace dataset_util {

namespace fs = std::filesystem;

namespace {

// The shortest decimal form that reads back as exactly `value` (10.05, not 10.050000000000001).
std::string ShortestDecimal(double value) {
  for (int precision = 6; precision < 17; ++precision) {
    std::ostringstream out;
    out << std::setprecision(precision) << value;
    if (std::strtod(out.str().c_str(), nullptr) == value) return out.str();
  }
  std::ostringstream out;
  out << std::setprecision(17) << value;
  return out.str();
}

}  // namespace

std::vector<TableLine> ReadTable(const std::string& path, bool commas) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  std::vector<TableLine> table;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (commas) std::replace(line.begin(), line.end(), ',', ' ');
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    TableLine entry;
    entry.line_number = line_number;
    std::istringstream fields(line);
    std::string field;
    while (fields >> field) entry.fields.push_back(field);
    // Blank by operator>>'s whitespace (e.g. only '\v' or '\f'): no fields for readers to index.
    if (entry.fields.empty()) continue;
    table.push_back(std::move(entry));
  }
  return table;
}

void FailAt(const std::string& path, int line_number, const std::string& message) {
  throw std::runtime_error(path + ":" + std::to_string(line_number) + ": " + message);
}

double ParseDouble(const std::string& field, const std::string& path, int line_number) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(field.c_str(), &end);
  if (end == field.c_str() || *end != '\0')
    FailAt(path, line_number, "'" + field + "' is not a number");
  if (!std::isfinite(value) || errno == ERANGE) {
    FailAt(path, line_number, "'" + field + "' is not a finite number");
  }
  return value;
}

int64_t ParseInt64(const std::string& field, const std::string& path, int line_number) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(field.c_str(), &end, 10);
  if (end == field.c_str() || *end != '\0' || errno == ERANGE) {
    FailAt(path, line_number, "'" + field + "' is not an integer");
  }
  return static_cast<int64_t>(value);
}

void RequireFields(const TableLine& line, int min_fields, int max_fields, const std::string& path,
                   const std::string& expected) {
  const int n = static_cast<int>(line.fields.size());
  if (n < min_fields || (max_fields >= 0 && n > max_fields)) {
    FailAt(path, line.line_number,
           "expected " + expected + ", found " + std::to_string(n) + " field(s)");
  }
}

void RequireIncreasing(double previous, double t, const std::string& path, int line_number) {
  if (!(t > previous)) {
    FailAt(path, line_number,
           "timestamp " + ShortestDecimal(t) + " does not increase (previous " +
               ShortestDecimal(previous) + ")");
  }
}

double NanosecondsToSeconds(int64_t ns) {
  const int64_t seconds = ns / 1000000000;
  const int64_t rest = ns % 1000000000;
  return static_cast<double>(seconds) + static_cast<double>(rest) * 1e-9;
}

cv::Mat ReadGray8(const std::string& path) {
  if (!IsFile(path)) throw std::runtime_error(path + ": image file not found");
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error(path + ": cannot decode image");
  return image;
}

void RequireSize(const cv::Mat& image, int width, int height, const std::string& path) {
  if (image.cols != width || image.rows != height) {
    throw std::runtime_error(path + ": image is " + std::to_string(image.cols) + "x" +
                             std::to_string(image.rows) + ", the calibration expects " +
                             std::to_string(width) + "x" + std::to_string(height));
  }
}

int NearestIndex(const std::vector<double>& sorted, double t, double max_diff) {
  if (sorted.empty()) return -1;
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), t);
  int best = -1;
  double best_diff = max_diff;
  const int hi = static_cast<int>(it - sorted.begin());
  for (int i : {hi - 1, hi}) {
    if (i < 0 || i >= static_cast<int>(sorted.size())) continue;
    const double diff = std::abs(sorted[i] - t);
    if (diff <= best_diff) {
      best_diff = diff;
      best = i;
      if (diff == 0.0) break;
    }
  }
  return best;
}

std::string JoinPath(const std::string& a, const std::string& b) {
  return (fs::path(a) / fs::path(b)).string();
}

bool IsFile(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

bool IsDirectory(const std::string& path) {
  std::error_code error;
  return fs::is_directory(path, error);
}

bool HasImageExtension(const std::string& name) {
  std::string extension = fs::path(name).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* known : {".png", ".jpg", ".jpeg", ".pgm", ".ppm", ".bmp", ".tif", ".tiff"}) {
    if (extension == known) return true;
  }
  return false;
}

std::vector<std::string> ListImages(const std::string& dir) {
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    if (entry.is_regular_file() && HasImageExtension(entry.path().filename().string())) {
      names.push_back(entry.path().string());
    }
  }
  if (error) throw std::runtime_error(dir + ": cannot list folder: " + error.message());
  std::sort(names.begin(), names.end());
  return names;
}

Rectifier::Rectifier(std::unique_ptr<CameraModel> model) : model_(std::move(model)) {
  undistorter_ = std::make_unique<Undistorter>(*model_);
}

cv::Mat Rectifier::Rectify(const cv::Mat& gray8) const {
  cv::Mat gray32;
  gray8.convertTo(gray32, CV_32F);
  return undistorter_->Undistort(gray32);
}

Frame ImageListDataset::Load(int i) const {
  Frame frame;
  frame.index = i;
  frame.timestamp = timestamps_.at(i);
  frame.path = paths_[i];
  const cv::Mat raw = ReadGray8(frame.path);
  RequireSize(raw, rectifier_->input().width, rectifier_->input().height, frame.path);
  frame.image = rectifier_->Rectify(raw);
  return frame;
}

}  // namespace dataset_util
}  // namespace pldvo
