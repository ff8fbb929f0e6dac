// Row-wise robust loss in square-root form, shared by the batched cost functions.
//
// For a whitened residual r and a ceres::LossFunction rho(s), s = r^2:
//   r~ = sign(r) sqrt(rho(r^2)),   dr~/dr = rho'(r^2) |r| / sqrt(rho(r^2)),
// so r~^2 = rho(r^2) exactly (the cost is the robust cost) and
// d(r~^2 / 2)/dx = rho'(r^2) r dr/dx (the gradient is the robust gradient). The Gauss-Newton
// matrix J~^T J~ weights a row by (rho' |r|)^2 / rho: 1 in Huber's quadratic zone and
// k^2 / (2 k |r| - k^2) beyond its threshold k (IRLS would use k / |r|), always in (0, 1].
// As r -> 0, dr~/dr -> sqrt(rho'(0)) = 1 for Ceres' losses.
#ifndef PLDVO_RESIDUALS_ROBUSTIFY_H_
#define PLDVO_RESIDUALS_ROBUSTIFY_H_

#include <ceres/loss_function.h>

#include <algorithm>
#include <cmath>

namespace pldvo {

// Returns r~ and writes dr~/dr to `*scale`. loss == nullptr: returns r, *scale = 1.
inline double RobustifyRow(const ceres::LossFunction* loss, double residual, double* scale) {
  if (loss == nullptr) {
    *scale = 1.0;
    return residual;
  }
  double rho[3];
  loss->Evaluate(residual * residual, rho);
  if (!(rho[0] > 0.0)) {  // r == 0 (or underflow): the limit.
    *scale = std::sqrt(std::max(rho[1], 0.0));
    return *scale * residual;
  }
  const double root = std::sqrt(rho[0]);
  *scale = rho[1] * std::abs(residual) / root;
  return residual >= 0.0 ? root : -root;
}

}  // namespace pldvo

#endif  // PLDVO_RESIDUALS_ROBUSTIFY_H_
