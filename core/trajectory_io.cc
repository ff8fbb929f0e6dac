#include "core/trajectory_io.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace pldvo {
namespace {

// A quaternion written with 4 decimals (the TUM ground truth) has a norm within 1e-4 of 1; a
// norm further than this from 1 means the line is not a rotation (e.g. columns swapped).
constexpr double kMaxQuaternionNormError = 1e-3;

[[noreturn]] void Fail(const std::string& path, int line_number, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line_number) + ": " + what);
}

// Parses a finite double occupying the whole token.
double ParseFinite(const std::string& token, const std::string& path, int line_number) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (end == token.c_str() || *end != '\0') {
    Fail(path, line_number, "'" + token + "' is not a number");
  }
  if (!std::isfinite(value) || errno == ERANGE) {
    Fail(path, line_number, "'" + token + "' is not a finite number");
  }
  return value;
}

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

Trajectory ReadTrajectoryTum(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open trajectory file");
  Trajectory trajectory;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::vector<std::string> tokens;
    std::string token;
    while (fields >> token) tokens.push_back(token);
    if (tokens.size() != 8) {
      Fail(path, line_number,
           "expected 8 fields 'timestamp tx ty tz qx qy qz qw', found " +
               std::to_string(tokens.size()));
    }
    double values[8];
    for (int i = 0; i < 8; ++i) values[i] = ParseFinite(tokens[i], path, line_number);
    const Eigen::Quaterniond rotation(values[7], values[4], values[5], values[6]);
    const double norm = rotation.norm();
    if (std::abs(norm - 1.0) > kMaxQuaternionNormError) {
      std::ostringstream what;
      what << "quaternion (qx qy qz qw) has norm " << norm << ", not 1";
      Fail(path, line_number, what.str());
    }
    if (!trajectory.empty() && !(values[0] > trajectory.back().timestamp)) {
      Fail(path, line_number,
           "timestamp " + ShortestDecimal(values[0]) + " does not increase (previous " +
               ShortestDecimal(trajectory.back().timestamp) + ")");
    }
    StampedPose pose;
    pose.timestamp = values[0];
    pose.world_from_cam = SE3(rotation, Eigen::Vector3d(values[1], values[2], values[3]));
    trajectory.push_back(pose);
  }
  return trajectory;
}

void WriteTumLine(const StampedPose& pose, std::ostream& out) {
  const Eigen::Vector3d& t = pose.world_from_cam.translation();
  const Eigen::Quaterniond& q = pose.world_from_cam.rotation();
  // 17 significant digits round-trip every double exactly; timestamps keep full precision too.
  const std::streamsize old_precision = out.precision(17);
  out << pose.timestamp << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' '
      << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  out.precision(old_precision);
}

void WriteTrajectoryTum(const Trajectory& trajectory, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot open for writing");
  out << "# timestamp tx ty tz qx qy qz qw (world_from_cam, TUM format)\n";
  for (const StampedPose& pose : trajectory) WriteTumLine(pose, out);
  out.flush();
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace pldvo
