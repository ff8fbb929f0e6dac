#include "core/camera_model.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

namespace pldvo {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d NanRay() {
  return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
}

// d(x / z, y / z) / d(x, y, z).
Eigen::Matrix<double, 2, 3> NormalizeJacobian(const Eigen::Vector3d& point_in_cam) {
  const double inv_z = 1.0 / point_in_cam.z();
  Eigen::Matrix<double, 2, 3> jacobian;
  jacobian << inv_z, 0.0, -point_in_cam.x() * inv_z * inv_z, 0.0, inv_z,
      -point_in_cam.y() * inv_z * inv_z;
  return jacobian;
}

class PinholeModel final : public CameraModel {
 public:
  explicit PinholeModel(const PinholeCamera& intrinsics) : camera_(intrinsics) {}
  std::string model_name() const override { return "pinhole"; }
  const PinholeCamera& intrinsics() const override { return camera_; }
  std::vector<double> distortion() const override { return {}; }
  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const override {
    return camera_.Project(point_in_cam);
  }
  Eigen::Matrix<double, 2, 3> ProjectJacobian(const Eigen::Vector3d& point_in_cam) const override {
    return camera_.ProjectJacobian(point_in_cam);
  }
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const override {
    return camera_.Unproject(pixel);
  }

 private:
  PinholeCamera camera_;
};

// OpenCV's radial-tangential model on normalised coordinates (x, y) = (X / Z, Y / Z):
//   r^2 = x^2 + y^2,  radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
//   x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
//   u = fx x_d + cx,  v = fy y_d + cy.
class RadtanModel final : public CameraModel {
 public:
  RadtanModel(const PinholeCamera& intrinsics, const std::vector<double>& distortion)
      : camera_(intrinsics),
        k1_(distortion[0]),
        k2_(distortion[1]),
        p1_(distortion[2]),
        p2_(distortion[3]),
        k3_(distortion[4]) {}
  std::string model_name() const override { return "radtan"; }
  const PinholeCamera& intrinsics() const override { return camera_; }
  std::vector<double> distortion() const override { return {k1_, k2_, p1_, p2_, k3_}; }

  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const override {
    const Eigen::Vector2d distorted = Distort(point_in_cam.hnormalized());
    return Eigen::Vector2d(camera_.fx * distorted.x() + camera_.cx,
                           camera_.fy * distorted.y() + camera_.cy);
  }

  Eigen::Matrix<double, 2, 3> ProjectJacobian(const Eigen::Vector3d& point_in_cam) const override {
    Eigen::Matrix<double, 2, 3> jacobian =
        DistortJacobian(point_in_cam.hnormalized()) * NormalizeJacobian(point_in_cam);
    jacobian.row(0) *= camera_.fx;
    jacobian.row(1) *= camera_.fy;
    return jacobian;
  }

  // Newton's method on x_d(x) = target from x = target (the distortion is a small perturbation
  // of the identity inside the image, so it converges quadratically in a few iterations).
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const override {
    const Eigen::Vector2d target((pixel.x() - camera_.cx) / camera_.fx,
                                 (pixel.y() - camera_.cy) / camera_.fy);
    Eigen::Vector2d point = target;
    constexpr int kMaxIterations = 50;
    constexpr double kConverged = 1e-14;  // normalised units: ~1e-11 px at f = 500
    for (int i = 0; i < kMaxIterations; ++i) {
      const Eigen::Vector2d error = Distort(point) - target;
      if (error.squaredNorm() < kConverged * kConverged) return point.homogeneous();
      const Eigen::Matrix2d jacobian = DistortJacobian(point);
      const double det = jacobian.determinant();
      if (!(std::abs(det) > 1e-12)) break;
      point -= jacobian.inverse() * error;
      if (!point.allFinite()) break;
    }
    // Accept a final error below 1e-9 (~5e-7 px) that round-off kept above kConverged.
    if (point.allFinite() && (Distort(point) - target).norm() < 1e-9) return point.homogeneous();
    return NanRay();
  }

 private:
  Eigen::Vector2d Distort(const Eigen::Vector2d& p) const {
    const double x = p.x(), y = p.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1_ + r2 * (k2_ + r2 * k3_));
    return Eigen::Vector2d(x * radial + 2.0 * p1_ * x * y + p2_ * (r2 + 2.0 * x * x),
                           y * radial + p1_ * (r2 + 2.0 * y * y) + 2.0 * p2_ * x * y);
  }
  // d(x_d, y_d) / d(x, y).
  Eigen::Matrix2d DistortJacobian(const Eigen::Vector2d& p) const {
    const double x = p.x(), y = p.y();
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1_ + r2 * (k2_ + r2 * k3_));
    const double dradial_dr2 = k1_ + r2 * (2.0 * k2_ + 3.0 * r2 * k3_);
    const double cross = 2.0 * x * y * dradial_dr2 + 2.0 * p1_ * x + 2.0 * p2_ * y;
    Eigen::Matrix2d jacobian;
    jacobian << radial + 2.0 * x * x * dradial_dr2 + 2.0 * p1_ * y + 6.0 * p2_ * x, cross, cross,
        radial + 2.0 * y * y * dradial_dr2 + 6.0 * p1_ * y + 2.0 * p2_ * x;
    return jacobian;
  }

  PinholeCamera camera_;
  double k1_, k2_, p1_, p2_, k3_;
};

// The FOV / ATAN model (Devernay & Faugeras 2001, as in PTAM, TUM monoVO and DSO) on
// normalised coordinates (x, y), r = |(x, y)|, a = 2 tan(w / 2):
//   (x_d, y_d) = f(r) (x, y),  f(r) = atan(a r) / (w r)   (so r_d = atan(a r) / w),
//   f(0) = a / w (the limit; DSO uses 1 at exactly r = 0, a discontinuity we avoid).
// Unprojection is closed form: r = tan(r_d w) / a, valid while r_d w < pi / 2.
class FovModel final : public CameraModel {
 public:
  FovModel(const PinholeCamera& intrinsics, double w)
      : camera_(intrinsics), w_(w), a_(2.0 * std::tan(0.5 * w)) {}
  std::string model_name() const override { return "fov"; }
  const PinholeCamera& intrinsics() const override { return camera_; }
  std::vector<double> distortion() const override { return {w_}; }

  Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const override {
    const Eigen::Vector2d normalized = point_in_cam.hnormalized();
    const double factor = Factor(normalized.norm());
    return Eigen::Vector2d(camera_.fx * factor * normalized.x() + camera_.cx,
                           camera_.fy * factor * normalized.y() + camera_.cy);
  }

  // d(f(r) p) / dp = f(r) I + (f'(r) / r) p p^T.
  Eigen::Matrix<double, 2, 3> ProjectJacobian(const Eigen::Vector3d& point_in_cam) const override {
    const Eigen::Vector2d normalized = point_in_cam.hnormalized();
    const double r = normalized.norm();
    const Eigen::Matrix2d distort_jacobian =
        Factor(r) * Eigen::Matrix2d::Identity() +
        FactorDerivativeOverR(r) * normalized * normalized.transpose();
    Eigen::Matrix<double, 2, 3> jacobian = distort_jacobian * NormalizeJacobian(point_in_cam);
    jacobian.row(0) *= camera_.fx;
    jacobian.row(1) *= camera_.fy;
    return jacobian;
  }

  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const override {
    const Eigen::Vector2d distorted((pixel.x() - camera_.cx) / camera_.fx,
                                    (pixel.y() - camera_.cy) / camera_.fy);
    const double r_d = distorted.norm();
    if (r_d == 0.0) return Eigen::Vector3d(0.0, 0.0, 1.0);
    if (!(r_d * w_ < 0.5 * kPi)) return NanRay();
    const double scale = std::tan(r_d * w_) / (a_ * r_d);
    return (scale * distorted).homogeneous();
  }

 private:
  // f(r) = atan(a r) / (w r); Taylor series for small a r (truncation (a r)^8 < 1e-16).
  double Factor(double r) const {
    const double u = a_ * r;
    if (u < 1e-2) {
      const double u2 = u * u;
      return a_ / w_ * (1.0 - u2 * (1.0 / 3.0 - u2 * (1.0 / 5.0 - u2 / 7.0)));
    }
    return std::atan(u) / (w_ * r);
  }
  // f'(r) / r = (a r / (1 + a^2 r^2) - atan(a r)) / (w r^3); Taylor series for small a r,
  // where the direct formula cancels (truncation (a r)^6 < 1e-12 relative, like the
  // cancellation error eps / (a r)^2 of the direct formula at the switch).
  double FactorDerivativeOverR(double r) const {
    const double u = a_ * r;
    if (u < 1e-2) {
      const double u2 = u * u;
      return a_ * a_ * a_ / w_ * (-2.0 / 3.0 + u2 * (4.0 / 5.0 - u2 * 6.0 / 7.0));
    }
    return (u / (1.0 + u * u) - std::atan(u)) / (w_ * r * r * r);
  }

  PinholeCamera camera_;
  double w_;
  double a_;
};

bool SampleInside(const Eigen::Vector2d& pixel, const PinholeCamera& camera) {
  return pixel.allFinite() && pixel.x() >= 0.0 && pixel.y() >= 0.0 &&
         pixel.x() <= camera.width - 1.0 && pixel.y() <= camera.height - 1.0;
}

// True when every border pixel of the pinhole `output` maps inside the input image. Interior
// pixels then do too: a radially symmetric, monotone distortion moves a pixel along the line
// to the principal point as its ray moves towards the axis, and the image rectangle is convex.
bool OutputFitsInside(const CameraModel& camera, const PinholeCamera& output) {
  const PinholeCamera& input = camera.intrinsics();
  auto fits = [&](double u, double v) {
    return SampleInside(camera.Project(output.Unproject(Eigen::Vector2d(u, v))), input);
  };
  for (int u = 0; u < output.width; ++u) {
    if (!fits(u, 0) || !fits(u, output.height - 1)) return false;
  }
  for (int v = 0; v < output.height; ++v) {
    if (!fits(0, v) || !fits(output.width - 1, v)) return false;
  }
  return true;
}

// The pinhole camera for the fov model: the input's principal point and fx, fy scaled by the
// smallest s (widest field of view) for which the whole output image samples inside the input.
PinholeCamera FovOutputCamera(const CameraModel& camera) {
  const PinholeCamera& input = camera.intrinsics();
  if (!SampleInside(Eigen::Vector2d(input.cx, input.cy), input)) {
    std::ostringstream message;
    message << "Undistorter: the principal point (" << input.cx << ", " << input.cy
            << ") lies outside the " << input.width << "x" << input.height << " image";
    throw std::invalid_argument(message.str());
  }
  auto scaled = [&](double s) {
    PinholeCamera output = input;
    output.fx = s * input.fx;
    output.fy = s * input.fy;
    return output;
  };
  // Bracket [lo, hi] with fits(hi) and !fits(lo); s = 1e-3 (a 179.9 degree field of view for
  // typical images) is the widest we consider.
  double hi = 1.0;
  while (!OutputFitsInside(camera, scaled(hi))) {
    hi *= 2.0;
    if (hi > 1e6) throw std::invalid_argument("Undistorter: no pinhole fits inside the fov image");
  }
  double lo = hi;
  while (OutputFitsInside(camera, scaled(lo))) {
    lo *= 0.5;
    if (lo < 1e-3) return scaled(hi);
  }
  for (int i = 0; i < 40; ++i) {  // relative width 2^-40 of the bracket
    const double mid = 0.5 * (lo + hi);
    (OutputFitsInside(camera, scaled(mid)) ? hi : lo) = mid;
  }
  return scaled(hi);
}

}  // namespace

std::unique_ptr<CameraModel> MakeCameraModel(const std::string& model,
                                             const PinholeCamera& intrinsics,
                                             const std::vector<double>& distortion) {
  const std::string intrinsics_error = intrinsics.Check();
  if (!intrinsics_error.empty()) {
    throw std::invalid_argument("camera model '" + model + "': " + intrinsics_error);
  }
  auto expect_count = [&](size_t count, const char* names) {
    if (distortion.size() != count) {
      std::ostringstream message;
      message << "camera model '" << model << "' takes " << count << " distortion values (" << names
              << "), got " << distortion.size();
      throw std::invalid_argument(message.str());
    }
    for (double value : distortion) {
      if (!std::isfinite(value)) {
        throw std::invalid_argument("camera model '" + model + "': distortion must be finite");
      }
    }
  };
  if (model == "pinhole") {
    expect_count(0, "none");
    return std::make_unique<PinholeModel>(intrinsics);
  }
  if (model == "radtan") {
    expect_count(5, "k1 k2 p1 p2 k3");
    return std::make_unique<RadtanModel>(intrinsics, distortion);
  }
  if (model == "fov") {
    expect_count(1, "w");
    if (!(distortion[0] > 0.0 && distortion[0] < kPi)) {
      std::ostringstream message;
      message << "camera model 'fov': w must lie in (0, pi), got " << distortion[0];
      throw std::invalid_argument(message.str());
    }
    return std::make_unique<FovModel>(intrinsics, distortion[0]);
  }
  throw std::invalid_argument("unknown camera model '" + model + "' (valid: pinhole, radtan, fov)");
}

Undistorter::Undistorter(const CameraModel& camera)
    : input_size_(camera.intrinsics()), output_camera_(camera.intrinsics()) {
  const std::string name = camera.model_name();
  if (name == "pinhole") {
    identity_ = true;
    return;
  }
  identity_ = false;
  const cv::Size size(input_size_.width, input_size_.height);
  if (name == "radtan") {
    const PinholeCamera& k = camera.intrinsics();
    const cv::Matx33d camera_matrix(k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0);
    const std::vector<double> distortion = camera.distortion();
    cv::initUndistortRectifyMap(camera_matrix, distortion, cv::noArray(), camera_matrix, size,
                                CV_16SC2, map_x_, map_y_);
    return;
  }
  // fov and any other model: build the float maps through the model, then convert them.
  output_camera_ = FovOutputCamera(camera);
  cv::Mat map_x(size, CV_32FC1), map_y(size, CV_32FC1);
  for (int v = 0; v < size.height; ++v) {
    float* row_x = map_x.ptr<float>(v);
    float* row_y = map_y.ptr<float>(v);
    for (int u = 0; u < size.width; ++u) {
      const Eigen::Vector2d source =
          camera.Project(output_camera_.Unproject(Eigen::Vector2d(u, v)));
      row_x[u] = static_cast<float>(source.x());
      row_y[u] = static_cast<float>(source.y());
    }
  }
  cv::convertMaps(map_x, map_y, map_x_, map_y_, CV_16SC2);
}

cv::Mat Undistorter::Remap(const cv::Mat& image, int interpolation) const {
  if (image.cols != input_size_.width || image.rows != input_size_.height) {
    std::ostringstream message;
    message << "Undistorter: image is " << image.cols << "x" << image.rows
            << " but the calibration is " << input_size_.width << "x" << input_size_.height;
    throw std::invalid_argument(message.str());
  }
  if (identity_) return image;
  cv::Mat undistorted;
  cv::remap(image, undistorted, map_x_, map_y_, interpolation, cv::BORDER_CONSTANT,
            cv::Scalar::all(0));
  return undistorted;
}

cv::Mat Undistorter::Undistort(const cv::Mat& image) const {
  return Remap(image, cv::INTER_LINEAR);
}

cv::Mat Undistorter::UndistortNearest(const cv::Mat& image) const {
  return Remap(image, cv::INTER_NEAREST);
}

}  // namespace pldvo
