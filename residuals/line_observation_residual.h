// Reprojection residual of a 3D line in one keyframe for windowed edge bundle adjustment
// (docs/edge_ba.md; the seed paper's future work, Yang & Scherer, ICRA 2017, Sec. VII). It is
// the point-to-line distance of the paper's eq. 3 with the roles of point and line swapped:
// the line is the projection of a 3D line variable, the points are the keyframe's observed edge
// pixels x_j (or a segment's two endpoints):
//
//   o_c = R o + t,  d_c = R d,            (the line's point and direction in the camera)
//   n_c = o_c x d_c,                      (normal of the plane through the camera centre and
//                                          the line = the line's Pluecker moment in the camera)
//   l   ~ K^-T n_c,                       (the projected image line, eq. "l ~ K' n")
//   r_j = sqrt_info_j * l^T (x_j; 1) / |(l_1, l_2)|
//       = sqrt_info_j * (n_c . m_j) / sqrt((n_1 / fx)^2 + (n_2 / fy)^2),   m_j = K^-1 (x_j; 1),
//
// the signed distance in pixels from x_j to the projected line, whitened. The residual is
// invariant to the scale of d and of n_c.
//
// Parameter blocks:
//   [0] cam_from_world, double[7] = [t, q] (SE3Manifold, residuals/se3_manifold.h);
//   [1] line_in_world,  double[6] = [o, d] (ceres::LineManifold<3>: o any point of the line,
//       d its unit direction; 4 tangent dimensions).
// Jacobians (analytic): dn_c / d(v, w) = [-[d_c]x, -[n_c]x] for the pose's left twist, lifted
// to the 7 parameters through PoseMinusJacobian; dn_c / do = -[d_c]x R and dn_c / dd = [o_c]x R
// are exact derivatives with respect to the line's ambient parameters (Ceres applies
// LineManifold::PlusJacobian). dr_j / dn_c = s_j (m_j / D - (n_c . m_j) / D^3 (n_1/fx^2,
// n_2/fy^2, 0)), D = sqrt((n_1/fx)^2 + (n_2/fy)^2).
//
// Weighting: sqrt_info_j = 1 / sqrt(Sigma_r), Sigma_r = PointToLineVariance(l, 0, x_j,
// sigma_px^2 diag(1, 1, 0)) (covariance_models.h): the projected line carries no measurement
// noise of its own, so for isotropic pixel noise Sigma_r = sigma_px^2; computed by the caller and
// held constant inside a solve. Robust loss (optional, not owned): row-wise square-root form
// (residuals/robustify.h), as in the tracking residuals.
// Validity: when the line passes (numerically) through the camera centre, D <= 1e-12 |n_c|,
// and the projection is undefined: Evaluate returns false (Ceres rejects the step).
// Evaluate() does no heap allocation.
#ifndef PLDVO_RESIDUALS_LINE_OBSERVATION_RESIDUAL_H_
#define PLDVO_RESIDUALS_LINE_OBSERVATION_RESIDUAL_H_

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <vector>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo {

constexpr int kLineAmbientSize = 6;  // [o, d]
constexpr int kLineTangentSize = 4;

// One observed edge pixel of the 3D line.
struct LineObservationPixel {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // pixels of the keyframe image (level 0)
  double sqrt_info = 1.0;                           // 1 / sqrt(Sigma_r), 1/px, >= 0
};

class LineObservationResidual : public ceres::CostFunction {
 public:
  // Throws std::invalid_argument on an empty batch, an invalid camera, or a non-finite pixel or
  // a negative / non-finite sqrt_info.
  LineObservationResidual(const PinholeCamera& camera, std::vector<LineObservationPixel> pixels,
                          const ceres::LossFunction* loss = nullptr);

  static LineObservationResidual* Create(const PinholeCamera& camera,
                                         std::vector<LineObservationPixel> pixels,
                                         const ceres::LossFunction* loss = nullptr) {
    return new LineObservationResidual(camera, std::move(pixels), loss);
  }

  // parameters[0] = cam_from_world (7), parameters[1] = line_in_world (6). jacobians[0] is
  // N x 7, jacobians[1] N x 6, row-major.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  int num_pixels() const { return static_cast<int>(pixels_.size()); }
  const std::vector<LineObservationPixel>& pixels() const { return pixels_; }

 private:
  const PinholeCamera camera_;
  const std::vector<LineObservationPixel> pixels_;
  std::vector<Eigen::Vector3d> rays_;  // m_j = K^-1 (x_j; 1)
  const ceres::LossFunction* loss_;
};

// The unnormalised image line l = K^-T (o_c x d_c) of a 3D line seen from cam_from_world,
// scaled so that (l_1, l_2) is a unit vector: l^T (u, v, 1) is the signed distance in pixels.
// Returns false when the line passes through the camera centre.
bool ProjectLine(const PinholeCamera& camera, const SE3& cam_from_world,
                 const Eigen::Vector3d& point_in_world, const Eigen::Vector3d& direction_in_world,
                 Eigen::Vector3d* line_in_image);

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_LINE_OBSERVATION_RESIDUAL_H_
