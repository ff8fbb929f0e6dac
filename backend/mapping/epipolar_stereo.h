// Small-baseline stereo of one keyframe pixel against a tracked frame (Engel, Sturm, Cremers,
// "Semi-Dense Visual Odometry for a Monocular Camera", ICCV 2013, Sec. 2.2): an SSD search over
// five equidistant samples along the epipolar line, restricted to the prior interval
// idepth +- 2 sigma, with the observation variance of the geometric and photometric disparity
// errors converted to inverse depth:
//   sigma_lambda(xi, pi)^2 = sigma_l^2 / <g, l>^2   (g, l: unit gradient, epipolar direction)
//   sigma_lambda(I)^2 = 2 sigma_I^2 / g_p^2         (g_p: gradient along the line)
//   sigma_d^2 = alpha^2 (sigma_lambda(xi, pi)^2 + sigma_lambda(I)^2),
//   alpha = d idepth / d lambda = 1 / |d tau / d idepth|;
// sigma_I^2 is raised to the match's residual variance SSD / 8 when that is larger
// (options.residual_intensity_noise).
// Geometry: a keyframe pixel x with inverse depth d appears in the current frame at
// tau(x, d) = pi(A + d B), A = K R K^-1 (x; 1), B = K t, (R, t) = cur_from_ref; d = 0 is the
// point at infinity, d -> infinity the epipole. See docs/mapping.md.
#ifndef PLDVO_BACKEND_MAPPING_EPIPOLAR_STEREO_H_
#define PLDVO_BACKEND_MAPPING_EPIPOLAR_STEREO_H_

#include <Eigen/Core>

#include "backend/mapping/mapping_options.h"
#include "core/image_pyramid.h"
#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

class EpipolarGeometry {
 public:
  // `pose_covariance`: of the tangent (t; w) of the left perturbation Exp(delta) * cur_from_ref
  // (the tracker's TrackingResult::pose_covariance), which PoseOffsetVar propagates to the
  // image; zero: none.
  EpipolarGeometry(const PinholeCamera& camera, const SE3& cur_from_ref,
                   const Matrix6d& pose_covariance = Matrix6d::Zero());

  const PinholeCamera& camera() const { return camera_; }
  const SE3& cur_from_ref() const { return cur_from_ref_; }
  // A(x) = K R K^-1 (x; 1): the homogeneous current pixel of x at infinity.
  Eigen::Vector3d InfinityPoint(const Eigen::Vector2d& pixel_in_ref) const {
    return krki_ * Eigen::Vector3d(pixel_in_ref.x(), pixel_in_ref.y(), 1.0);
  }
  // B = K t.
  const Eigen::Vector3d& ScaledTranslation() const { return kt_; }

  // tau(x, d); false when the point is on or behind the current image plane.
  bool Project(const Eigen::Vector2d& pixel_in_ref, double idepth,
               Eigen::Vector2d* pixel_in_cur) const;
  // d tau / d d at (x, d) (pixels per 1/m). Requires a valid projection.
  Eigen::Vector2d IdepthJacobian(const Eigen::Vector2d& pixel_in_ref, double idepth) const;
  // The inverse depth d with tau(x, d) = pixel_in_cur for a pixel on x's epipolar line, solved
  // in the image coordinate along which the line runs more steeply (`direction_in_cur`).
  double IdepthFromCurPixel(const Eigen::Vector2d& pixel_in_ref,
                            const Eigen::Vector2d& pixel_in_cur,
                            const Eigen::Vector2d& direction_in_cur) const;
  // Unit direction of x's epipolar line in the keyframe (towards the current camera's epipole
  // up to sign); false when x is (nearly) the epipole or there is no baseline.
  bool EpipolarDirectionInRef(const Eigen::Vector2d& pixel_in_ref, Eigen::Vector2d* dir) const;
  // Variance of tau(x, d)'s offset along the unit `normal_in_cur` caused by the pose error,
  // n^T J Sigma J^T n with J = d tau / d delta = d pi / dY [d I, -[Y]x], Y = R K^-1 (x; 1) + d t
  // (the point times d, so that d = 0 is the point at infinity). Requires a valid projection.
  double PoseOffsetVar(const Eigen::Vector2d& pixel_in_ref, double idepth,
                       const Eigen::Vector2d& normal_in_cur) const;

 private:
  PinholeCamera camera_;
  SE3 cur_from_ref_;
  Eigen::Matrix3d rotation_;  // of cur_from_ref, once rather than per pixel
  Eigen::Matrix3d krki_;
  Eigen::Vector3d kt_;
  Eigen::Vector3d epipole_in_ref_h_;  // K c, c = -R^T t the current centre in the keyframe
  Matrix6d pose_covariance_;
  bool has_pose_covariance_ = false;
};

enum class StereoStatus {
  kOk = 0,
  kOutside,             // samples or the match leave an image, or the point is behind a camera
  kBadGeometry,         // gradient orthogonal to the epipolar line, scale change, no baseline
  kSearchTooLong,       // the prior interval spans more than max_search_length_px
  kTruncated,           // part of the prior interval leaves the current image (the true match
                        // may lie there; the best sampled step is no evidence)
  kNotUnique,           // second-best SSD too close to the best (counts towards the blacklist)
  kLargeError,          // best SSD above max_ssd_rms (counts towards the blacklist)
  kIntervalEnd,         // the best SSD is at an end of the prior interval that is not a global
                        // bound (options.ssd_interval_end)
  kLineIllConditioned,  // line-guided: epipolar line and edge nearly parallel
  kLineOutOfRange,      // line-guided: the intersection lies outside the prior interval
};
const char* StereoStatusName(StereoStatus status);

// The five keyframe samples around x along its epipolar line (1 px apart) and where consecutive
// samples fall in the current frame.
struct EpipolarPatch {
  float ref[5] = {0.f, 0.f, 0.f, 0.f, 0.f};
  Eigen::Vector2d dir_ref = Eigen::Vector2d::Zero();   // unit epipolar direction in the keyframe
  Eigen::Vector2d step_cur = Eigen::Vector2d::Zero();  // current-frame offset of one sample step
  double gradient_epipolar_cos = 0.0;                  // |<g, l>| with unit g and l
};

// Builds the patch of x; the keyframe step is mapped to the current frame at idepth_centre.
StereoStatus MakeEpipolarPatch(const ImagePyramid& keyframe, const EpipolarGeometry& geometry,
                               const Eigen::Vector2d& pixel_in_ref, double idepth_centre,
                               const MappingOptions& options, EpipolarPatch* patch);

// Sum of squared differences of the patch against the current samples centred at pixel_in_cur;
// +infinity when a sample cannot be taken.
double PatchSsd(const ImagePyramid& current, const EpipolarPatch& patch,
                const Eigen::Vector2d& pixel_in_cur);

// Disparity variances of Engel 2013 (pixels^2 along the current epipolar line).
// Geometric: the epipolar line's position variance (pixels^2) over cos^2 of the gradient angle.
double GeometricDisparityVar(const EpipolarPatch& patch, double epipolar_position_var);
double PhotometricDisparityVar(const ImagePyramid& current, const EpipolarPatch& patch,
                               const Eigen::Vector2d& pixel_in_cur, double sigma_intensity);

struct StereoObservation {
  double idepth = 0.0;
  double idepth_var = 0.0;
  Eigen::Vector2d pixel_in_cur = Eigen::Vector2d::Zero();
  double disparity_var = 0.0;  // pixels^2 along the epipolar line
  double ssd = 0.0;            // 5-sample SSD at the match
  // The part of idepth_var that every observation of the pixel shares on top of
  // options.stereo_error_correlation (line-guided: the keyframe edge's error; SSD: 0).
  double shared_idepth_var = 0.0;
};

// The exhaustive SSD search along x's epipolar line over [idepth_min, idepth_max] (steps of
// about options.ssd_search_step_px that divide the patch's sample spacing, each line sample
// interpolated once; parabola sub-pixel refinement), with the variance above; with
// options.ssd_ambiguity_variance the variance also gets the spread of the other SSD minima,
// sum_k w_k (d_k - d)^2 / (1 + sum_k w_k), w_k = exp(-(SSD_k - SSD_best) / (4 sigma_I^2)) the
// likelihood ratio of minimum k against the best (docs/mapping.md, "Search step and ambiguous
// matches"). Every step of the interval must be sampled: when part of it leaves the current
// image the search returns kTruncated, because the best of the remaining steps is then a wrong
// match whenever the true one lies outside (under forward motion the bottom rows' matches leave
// the image first; docs/mapping.md, "Truncated searches"). With options.ssd_interval_end other than
// accept, a best step at an end of [idepth_min, idepth_max] that is not a global bound returns
// kIntervalEnd.
StereoStatus SearchEpipolarSsd(const ImagePyramid& current, const EpipolarGeometry& geometry,
                               const EpipolarPatch& patch, const Eigen::Vector2d& pixel_in_ref,
                               double idepth_min, double idepth_max, const MappingOptions& options,
                               StereoObservation* observation);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_EPIPOLAR_STEREO_H_
