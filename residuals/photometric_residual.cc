#include "residuals/photometric_residual.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include "residuals/batched_reprojection.h"
#include "residuals/robustify.h"
#include "residuals/se3_manifold.h"

namespace pldvo {
namespace {

// Sampling area [1, w - 2) x [1, h - 2): bilinear lookups then touch only pixels whose
// central-difference gradient is defined (ImagePyramid leaves the one-pixel border at 0), and
// the bicubic 4x4 neighbourhood (rows and columns floor - 1 .. floor + 2) stays in the image.
constexpr double kSamplingBorder = 1.0;

// I_cur and its gradient (x = column, y = row) at a sub-pixel position inside the sampling
// area. With gradient == false, gx and gy may be left unset.
struct BilinearSampler {
  const ImagePyramid& pyramid;
  int level;
  void operator()(double x, double y, bool /*gradient*/, double* f, double* gx, double* gy) const {
    const Eigen::Vector3f sample = pyramid.Sample(level, x, y);
    *f = sample[0];
    *gx = sample[1];
    *gy = sample[2];
  }
};

template <class Interpolator>
struct BicubicSampler {
  const Interpolator& interpolator;
  void operator()(double x, double y, bool gradient, double* f, double* gx, double* gy) const {
    // Ceres' grids are indexed (row, column) = (y, x).
    interpolator.Evaluate(y, x, f, gradient ? gy : nullptr, gradient ? gx : nullptr);
  }
};

[[noreturn]] void ThrowInvalid(int line, const std::string& what) {
  std::ostringstream message;
  message << __FILE__ << ":" << line << ": PhotometricResidual: " << what;
  throw std::invalid_argument(message.str());
}

}  // namespace

PhotometricResidual::PhotometricResidual(const ImagePyramid& cur_pyramid, int level,
                                         const PinholeCamera& camera,
                                         std::vector<PhotometricObservation> observations,
                                         const ceres::LossFunction* loss,
                                         ImageInterpolation interpolation,
                                         BrightnessModel brightness)
    : cur_pyramid_(cur_pyramid),
      level_(level),
      camera_(camera),
      observations_(std::move(observations)),
      loss_(loss),
      interpolation_(interpolation),
      brightness_(brightness) {
  if (observations_.empty()) ThrowInvalid(__LINE__, "empty batch");
  if (level < 0 || level >= cur_pyramid.num_levels()) {
    ThrowInvalid(__LINE__, "level " + std::to_string(level) + " outside the pyramid's " +
                               std::to_string(cur_pyramid.num_levels()) + " levels");
  }
  const std::string camera_error = camera.Check();
  if (!camera_error.empty()) ThrowInvalid(__LINE__, "camera: " + camera_error);
  if (camera.width != cur_pyramid.width(level) || camera.height != cur_pyramid.height(level)) {
    ThrowInvalid(__LINE__, "camera size " + std::to_string(camera.width) + "x" +
                               std::to_string(camera.height) + " differs from level " +
                               std::to_string(level) + " size " +
                               std::to_string(cur_pyramid.width(level)) + "x" +
                               std::to_string(cur_pyramid.height(level)));
  }
  rays_in_ref_.reserve(observations_.size());
  for (size_t i = 0; i < observations_.size(); ++i) {
    const PhotometricObservation& o = observations_[i];
    if (!o.pixel_in_ref.allFinite() || !std::isfinite(o.intensity_ref) || !(o.idepth >= 0.0) ||
        !std::isfinite(o.idepth) || !(o.sqrt_info >= 0.0) || !std::isfinite(o.sqrt_info)) {
      ThrowInvalid(__LINE__, "observation " + std::to_string(i) +
                                 " has a non-finite value, a negative idepth or sqrt_info");
    }
    rays_in_ref_.push_back(camera_.Unproject(o.pixel_in_ref));
  }
  if (interpolation_ == ImageInterpolation::kBicubic) {
    grid_ = std::make_unique<const IntensityGrid>(cur_pyramid.IntensityData(level), 0,
                                                  cur_pyramid.height(level), 0,
                                                  cur_pyramid.width(level));
    bicubic_ = std::make_unique<const BicubicInterpolator>(*grid_);
  }
  valid_.assign(observations_.size(), 0);
  set_num_residuals(static_cast<int>(observations_.size()));
  mutable_parameter_block_sizes()->push_back(kPoseAmbientSize);
  if (brightness_ == BrightnessModel::kAffine) {
    mutable_parameter_block_sizes()->push_back(kBrightnessSize);
  }
}

namespace {

// Calls body(sampler) with the sampler of the interpolation.
template <class Interpolator, class Body>
void WithSampler(ImageInterpolation interpolation, const ImagePyramid& pyramid, int level,
                 const Interpolator* bicubic, Body&& body) {
  if (interpolation == ImageInterpolation::kBicubic) {
    body(BicubicSampler<Interpolator>{*bicubic});
  } else {
    body(BilinearSampler{pyramid, level});
  }
}

// One row: residual and (optionally) its Jacobians in the pose tangent (6) and the brightness
// (2: a, b). Returns validity.
template <class Sampler>
inline bool PhotometricRow(const Sampler& sample, const PinholeCamera& camera,
                           const PhotometricObservation& o, const Eigen::Vector3d& ray_in_ref,
                           const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                           double root_gain, double inverse_root_gain, double bias,
                           const ceres::LossFunction* loss, double* residual,
                           double* jacobian_tangent, double* jacobian_brightness = nullptr) {
  // q = R K^-1 (x; 1) + d t = d * point_in_cur.
  const Eigen::Vector3d q = rotation * ray_in_ref + o.idepth * translation;
  const double u_over = q.x() / q.z();
  const double v_over = q.y() / q.z();
  const double u = camera.fx * u_over + camera.cx;
  const double v = camera.fy * v_over + camera.cy;
  const double max_u = camera.width - 1 - kSamplingBorder;
  const double max_v = camera.height - 1 - kSamplingBorder;
  if (!(q.z() > 0.0) || !(u >= kSamplingBorder && v >= kSamplingBorder && u < max_u && v < max_v)) {
    *residual = 0.0;
    if (jacobian_tangent != nullptr) std::fill(jacobian_tangent, jacobian_tangent + 6, 0.0);
    if (jacobian_brightness != nullptr) {
      std::fill(jacobian_brightness, jacobian_brightness + kBrightnessSize, 0.0);
    }
    return false;
  }
  double intensity_cur, gx, gy;
  sample(u, v, jacobian_tangent != nullptr, &intensity_cur, &gx, &gy);
  // e^{-a/2} (e^a I_ref + b - I_cur) with root_gain = e^{a/2}, inverse_root_gain = e^{-a/2},
  // bias = b (the header's symmetric form); I_ref - I_cur exactly when a = b = 0.
  double scale;
  *residual = RobustifyRow(
      loss,
      o.sqrt_info * (root_gain * o.intensity_ref + inverse_root_gain * (bias - intensity_cur)),
      &scale);
  if (jacobian_tangent != nullptr) {
    // c = g^T dpi/dq (1x3); dr/dxi = -w [d c, (q x c)^T] since c^T (-[q]x) = (q x c)^T.
    const double inv_z = 1.0 / q.z();
    const double gfx = gx * camera.fx * inv_z;
    const double gfy = gy * camera.fy * inv_z;
    const Eigen::Vector3d c(gfx, gfy, -(gfx * u_over + gfy * v_over));
    const double w = -o.sqrt_info * scale * inverse_root_gain;
    Eigen::Map<Eigen::Matrix<double, 6, 1>> row(jacobian_tangent);
    row.head<3>() = (w * o.idepth) * c;
    row.tail<3>() = w * q.cross(c);
  }
  if (jacobian_brightness != nullptr) {
    // dr/da = w (e^{a/2} I_ref - e^{-a/2} (b - I_cur)) / 2, dr/db = w e^{-a/2}.
    const double w = o.sqrt_info * scale;
    jacobian_brightness[0] =
        0.5 * w * (root_gain * o.intensity_ref - inverse_root_gain * (bias - intensity_cur));
    jacobian_brightness[1] = w * inverse_root_gain;
  }
  return true;
}

}  // namespace

bool PhotometricResidual::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const bool with_brightness = brightness_ == BrightnessModel::kAffine;
  EvaluateRows(parameters, residuals, jacobians != nullptr ? jacobians[0] : nullptr, nullptr,
               jacobians != nullptr && with_brightness ? jacobians[1] : nullptr);
  return true;
}

bool PhotometricResidual::EvaluatePoseTangent(double const* const* parameters, double* residuals,
                                              double* jacobian_tangent) const {
  EvaluateRows(parameters, residuals, nullptr, jacobian_tangent, nullptr);
  return true;
}

void PhotometricResidual::EvaluateRows(double const* const* parameters, double* residuals,
                                       double* jacobian_ambient, double* jacobian_tangent,
                                       double* jacobian_brightness) const {
  const SE3 cur_from_ref = PoseFromParameters(parameters[0]);
  const Eigen::Matrix3d rotation = cur_from_ref.rotation_matrix();
  const Eigen::Vector3d& translation = cur_from_ref.translation();
  const bool with_brightness = brightness_ == BrightnessModel::kAffine;
  const double root_gain = with_brightness ? std::exp(0.5 * parameters[1][0]) : 1.0;
  const double inverse_root_gain = 1.0 / root_gain;
  const double bias = with_brightness ? parameters[1][1] : 0.0;
  const MinusJacobianMatrix minus_jacobian =
      jacobian_ambient != nullptr ? PoseMinusJacobian(parameters[0]) : MinusJacobianMatrix::Zero();
  const int n = num_observations();
  WithSampler(interpolation_, cur_pyramid_, level_, bicubic_.get(), [&](const auto& sample) {
    double row_tangent[kPoseTangentSize];
    for (int i = 0; i < n; ++i) {
      double* tangent = jacobian_tangent != nullptr   ? jacobian_tangent + i * kPoseTangentSize
                        : jacobian_ambient != nullptr ? row_tangent
                                                      : nullptr;
      valid_[i] = PhotometricRow(
          sample, camera_, observations_[i], rays_in_ref_[i], rotation, translation, root_gain,
          inverse_root_gain, bias, loss_, residuals + i, tangent,
          jacobian_brightness != nullptr ? jacobian_brightness + i * kBrightnessSize : nullptr);
      if (jacobian_ambient != nullptr) {
        LiftTangentJacobian(minus_jacobian, row_tangent, 1,
                            jacobian_ambient + i * kPoseAmbientSize);
      }
    }
  });
}

void PhotometricResidual::EvaluateTangent(const SE3& cur_from_ref, double* residuals,
                                          double* jacobian_tangent, std::uint8_t* valid) const {
  const Eigen::Matrix3d rotation = cur_from_ref.rotation_matrix();
  const Eigen::Vector3d& translation = cur_from_ref.translation();
  const int n = num_observations();
  WithSampler(interpolation_, cur_pyramid_, level_, bicubic_.get(), [&](const auto& sample) {
    for (int i = 0; i < n; ++i) {
      const bool ok = PhotometricRow(
          sample, camera_, observations_[i], rays_in_ref_[i], rotation, translation, 1.0, 1.0, 0.0,
          loss_, residuals + i,
          jacobian_tangent != nullptr ? jacobian_tangent + i * kPoseTangentSize : nullptr);
      if (valid != nullptr) valid[i] = ok;
    }
  });
}

void PhotometricResidual::IntensityErrors(const SE3& cur_from_ref, double* errors,
                                          std::uint8_t* valid) const {
  const Eigen::Matrix3d rotation = cur_from_ref.rotation_matrix();
  const Eigen::Vector3d& translation = cur_from_ref.translation();
  const int n = num_observations();
  WithSampler(interpolation_, cur_pyramid_, level_, bicubic_.get(), [&](const auto& sample) {
    for (int i = 0; i < n; ++i) {
      PhotometricObservation unweighted = observations_[i];
      unweighted.sqrt_info = 1.0;
      const bool ok = PhotometricRow(sample, camera_, unweighted, rays_in_ref_[i], rotation,
                                     translation, 1.0, 1.0, 0.0, nullptr, errors + i, nullptr);
      if (valid != nullptr) valid[i] = ok;
    }
  });
}

std::vector<Eigen::Vector2d> PhotometricResidual::ReprojectedPixels(
    const SE3& cur_from_ref, std::vector<std::uint8_t>* valid) const {
  return ReprojectRays(camera_, rays_in_ref_, observations_, cur_from_ref, valid,
                       [&](double* residuals, std::uint8_t* row_valid) {
                         EvaluateTangent(cur_from_ref, residuals, nullptr, row_valid);
                       });
}

int PhotometricResidual::num_valid() const { return CountValid(valid_); }

}  // namespace pldvo
