// The pose parameter block and its manifold.
//
// A pose is stored as double[7] = [tx ty tz qx qy qz qw] (translation, then the unit quaternion
// in Eigen's coefficient order) and holds a transform b_from_a: p_b = R p_a + t. In tracking the
// block is cur_from_ref.
//
// Tangent convention (the one every cost function in pldvo uses): a twist delta = (v; w) in R^6,
// translational part first (core/se3.h), applied by LEFT multiplication:
//   Plus(x, delta)  = Exp(delta) * x,
//   Minus(y, x)     = Log(y * x^-1),
// (the quaternion is kept on x's side of the double cover, and Minus takes the rotation angle in
// [0, 2 pi) so that Plus(x, Minus(y, x)) == y holds coefficient-wise, sign included),
// so delta is expressed in frame b (for cur_from_ref: the current camera frame) and
// d(Exp(delta) * p_b) / d delta at 0 = [I, -[p_b]x].
//
// Cost functions compute their Jacobians in this 6-D tangent space and lift them to the 7
// ambient parameters with J_ambient(1x7) = J_tangent(1x6) * MinusJacobian(x) (6x7), which
// satisfies J_ambient * PlusJacobian(x) = J_tangent because MinusJacobian(x) * PlusJacobian(x) =
// I_6. That is what Ceres (and ceres::GradientChecker) consume; the radial quaternion direction,
// which the manifold never moves along, receives an arbitrary but harmless value.
#ifndef PLDVO_RESIDUALS_SE3_MANIFOLD_H_
#define PLDVO_RESIDUALS_SE3_MANIFOLD_H_

#include <ceres/manifold.h>

#include <Eigen/Core>

#include "core/se3.h"

namespace pldvo {

constexpr int kPoseAmbientSize = 7;
constexpr int kPoseTangentSize = 6;

using PlusJacobianMatrix =
    Eigen::Matrix<double, kPoseAmbientSize, kPoseTangentSize, Eigen::RowMajor>;
using MinusJacobianMatrix =
    Eigen::Matrix<double, kPoseTangentSize, kPoseAmbientSize, Eigen::RowMajor>;

// [tx ty tz qx qy qz qw] -> SE3 (the quaternion is normalised).
SE3 PoseFromParameters(const double* parameters);
// SE3 -> [tx ty tz qx qy qz qw], with qw >= 0.
void PoseToParameters(const SE3& b_from_a, double* parameters);

// d Plus(x, delta) / d delta at delta = 0 (7x6).
PlusJacobianMatrix PosePlusJacobian(const double* x);
// d Minus(y, x) / d y at y = x (6x7). The lifting matrix of every cost function.
MinusJacobianMatrix PoseMinusJacobian(const double* x);

// J_ambient (rows x 7, row-major) = J_tangent (rows x 6, row-major) * minus_jacobian.
// `jacobian_ambient` must not alias `jacobian_tangent`.
inline void LiftTangentJacobian(const MinusJacobianMatrix& minus_jacobian,
                                const double* jacobian_tangent, int rows,
                                double* jacobian_ambient) {
  // MinusJacobian = [I, A; 0, B] (A = [t]x dw/dq, B = dw/dq, both 3x4): exploit the identity and
  // zero blocks (24 instead of 42 multiply-adds per row). Plain loops over the row-major data:
  // per-row Eigen expressions this small stay out-of-line calls in the sanitizer build (-O1),
  // where they were 8% of the test suite's time.
  const double* m = minus_jacobian.data();  // row k at m + 7 k
  for (int r = 0; r < rows; ++r) {
    const double* j = jacobian_tangent + r * kPoseTangentSize;  // (j_v, j_w)
    double* out = jacobian_ambient + r * kPoseAmbientSize;
    out[0] = j[0];
    out[1] = j[1];
    out[2] = j[2];
    for (int c = 3; c < kPoseAmbientSize; ++c) {
      const double v = j[0] * m[c] + j[1] * m[7 + c] + j[2] * m[14 + c];        // j_v A
      const double w = j[3] * m[21 + c] + j[4] * m[28 + c] + j[5] * m[35 + c];  // j_w B
      out[c] = v + w;
    }
  }
}

// The manifold of the pose block above: SE(3) with left-multiplicative twist updates.
class SE3Manifold : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseAmbientSize; }
  int TangentSize() const override { return kPoseTangentSize; }
  // x_plus_delta = Exp(delta) * x.
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  // 7x6, row-major.
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // y_minus_x = Log(y * x^-1).
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  // 6x7, row-major.
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_SE3_MANIFOLD_H_
