// Camera models with distortion, their projection Jacobians, and undistortion of whole images
// to an ideal pinhole camera through a precomputed remap.
// Models: pinhole; radtan (OpenCV k1 k2 p1 p2 k3); fov (the ATAN model of TUM monoVO,
// Devernay & Faugeras: r_d = atan(2 r tan(w/2)) / w).
// All models share the pixel convention of core/pinhole_camera.h and take pixel intrinsics
// (fx fy cx cy in pixels). The formulas are in docs/cameras.md.
#ifndef PLDVO_CORE_CAMERA_MODEL_H_
#define PLDVO_CORE_CAMERA_MODEL_H_

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/pinhole_camera.h"

namespace pldvo {

class CameraModel {
 public:
  virtual ~CameraModel() = default;
  virtual std::string model_name() const = 0;  // "pinhole" | "radtan" | "fov"
  // Intrinsics (fx fy cx cy), image size and distortion parameters as in camera.yaml.
  virtual const PinholeCamera& intrinsics() const = 0;
  virtual std::vector<double> distortion() const = 0;
  // Distorted pixel of a point in the camera frame (z > 0), and d(pixel)/d(point).
  virtual Eigen::Vector2d Project(const Eigen::Vector3d& point_in_cam) const = 0;
  virtual Eigen::Matrix<double, 2, 3> ProjectJacobian(
      const Eigen::Vector3d& point_in_cam) const = 0;
  // The ray (z = 1) through a distorted pixel. Returns a vector of NaN when the pixel has no ray
  // with z > 0 (fov: beyond the 90 degree circle r_d w >= pi/2; radtan: the iterative inversion
  // did not converge, which happens only far outside the calibrated image).
  virtual Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const = 0;
};

// Builds a model from its name and parameters; throws std::invalid_argument naming what is
// wrong (unknown model, wrong number of distortion parameters, non-positive focal length or
// size, fov w outside (0, pi)). Distortion: pinhole {}, radtan {k1, k2, p1, p2, k3}, fov {w}.
std::unique_ptr<CameraModel> MakeCameraModel(const std::string& model,
                                             const PinholeCamera& intrinsics,
                                             const std::vector<double>& distortion);

// Undistorts images of a camera model to an ideal pinhole camera of the same size (for a
// pinhole model, the identity without a remap). The remap maps are computed once in the
// constructor; Undistort() does one cv::remap (bilinear, black outside the input image).
// Output camera: radtan keeps K (as cv::initUndistortRectifyMap with newK = K); fov keeps the
// principal point and scales fx, fy by the largest-field-of-view factor s for which every
// output pixel samples inside the input image (no black border; see docs/cameras.md).
class Undistorter {
 public:
  explicit Undistorter(const CameraModel& camera);
  const PinholeCamera& output_camera() const { return output_camera_; }
  // Any cv::remap-able type (CV_8U, CV_32F, 1 to 4 channels). Throws std::invalid_argument
  // naming both sizes when the image size differs from the calibration. For a pinhole model the
  // returned Mat shares its data with `image`.
  cv::Mat Undistort(const cv::Mat& image) const;
  // The same remap with nearest-neighbour sampling, for depth images: bilinear sampling would
  // invent depths between the two surfaces at an occlusion boundary.
  cv::Mat UndistortNearest(const cv::Mat& image) const;
  bool is_identity() const { return identity_; }

 private:
  cv::Mat Remap(const cv::Mat& image, int interpolation) const;

  PinholeCamera input_size_;
  PinholeCamera output_camera_;
  bool identity_ = true;
  // Fixed-point maps from cv::convertMaps (CV_16SC2 and CV_16UC1): the same 1/32 pixel
  // interpolation table cv::remap uses for float maps, without the per-call conversion.
  cv::Mat map_x_, map_y_;
};

}  // namespace pldvo

#endif  // PLDVO_CORE_CAMERA_MODEL_H_
