// The least-squares problem of one window of photometric + line bundle adjustment
// (docs/windowed_ba.md), built by a problem builder selected by name from
// WindowedBAOptions::problem_builder.
//
// Variables: the cam_from_world pose of each of the newest `window` keyframes (double[7],
// SE3Manifold), each keyframe's affine brightness {a, b} (double[2]) and the inverse depth of
// each selected point in its host keyframe (double[1], marked eliminated for the Schur solve).
// Residuals, all weighted at the input estimates (the linearisation point) by their covariance
// models and robustified (WeightingOptions):
//   - photometric (eq. 2, HostTargetPhotometricResidual): each selected point's pattern in every
//     other window keyframe where its centre reprojects inside the image, sqrt_info per row from
//     Sigma_f = 2 sigma_I^2 + (g^T J_d)^2 V (eq. 5), V the depth filter's variance of the point;
//   - point-to-line (eq. 3, HostTargetPointToLineResidual): each selected point on an edge with
//     a line observation in another window keyframe, sqrt_info from Sigma_g (eq. 6);
//   - inverse-depth prior: N(input, (idepth_prior_scale^2) V) on each point (see the options);
//   - brightness prior: N(input, diag(sigma_a^2, sigma_b^2)) on every keyframe's {a, b} but the
//     oldest's (with brightness affine);
//   - with WindowedBAOptions::marginalize, the window's prior (windowed_ba_prior.h) on the poses
//     of its keyframes, a PosePriorResidual, unless the window still holds a keyframe the prior
//     has marginalised.
//
// Gauge. Monocular BA is invariant to a similarity of the world (7 DOF), the photometric rows
// also to an affine change of the radiance (2 DOF: every a_k + c, and b_k - e^{a_k} beta).
// The oldest pose is held constant (6 DOF) and the scale by a BaselinePriorResidual between the
// oldest keyframe and the next one (or the farthest one when that baseline is below 1e-3 of the
// largest), holding their distance at its input value: exactly 7 DOF, so every other pose,
// including the second one, is refined (holding the two oldest poses constant would remove 12,
// freezing 5 DOF of the second pose). The data are exactly invariant to scaling the world about
// the fixed camera (inverse depths scale inversely), so the prior's residual is zero at the
// optimum for any sigma: it fixes the scale without trading off against the data (the weak
// inverse-depth priors, when on, also carry the inputs' scale and trade off slightly). The oldest
// keyframe's brightness is held constant (the 2-DOF brightness gauge). When every baseline is
// zero (pure rotation), the second pose is held constant instead.
#ifndef PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_PROBLEM_BUILDER_H_
#define PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_PROBLEM_BUILDER_H_

#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "backend/optimization/least_squares_problem.h"
#include "backend/windowed_ba/windowed_ba_options.h"
#include "backend/windowed_ba/windowed_ba_window.h"

namespace pldvo {

// A selected point: its host (window position) and index in that keyframe's points.
struct WindowedBAProblemPoint {
  int host = -1;
  int point_index = -1;
};

// The problem with the parameter arrays it points into. Movable (the arrays live in vectors that
// are never resized after the blocks are added), not copyable.
struct WindowedBAProblem {
  std::vector<int> keyframe_indices;  // window position -> index into WindowedBAWindow::keyframes
  std::vector<std::array<double, 7>> poses;       // cam_from_world
  std::vector<std::array<double, 2>> brightness;  // {a, b}
  std::vector<WindowedBAProblemPoint> points;     // the points that entered the problem
  std::vector<double> idepths;                    // one per entry of `points`
  LeastSquaresProblem problem;
  // The scale gauge: window positions of the two keyframes of the baseline prior (-1: none).
  int baseline_keyframe_a = -1;
  int baseline_keyframe_b = -1;
  double baseline = 0.0;
  // Marginalisation (marginalization.h): the residual blocks of the points hosted in the oldest
  // keyframe (photometric, point-to-line, inverse-depth prior) and the prior's block (-1: none).
  std::vector<int> oldest_host_blocks;
  int prior_block = -1;
  // Statistics.
  int num_candidates = 0;  // selected by SelectWindowPoints, before the min_targets check
  int num_photometric_blocks = 0;
  int num_outlier_targets = 0;  // photometric targets left out by outlier_energy_factor
  int num_photometric_rows = 0;
  int num_line_rows = 0;
  int num_prior_keyframes = 0;  // window keyframes the prior constrains
};

class WindowedBAProblemBuilder {
 public:
  virtual ~WindowedBAProblemBuilder() = default;
  // Throws std::invalid_argument on a malformed window (CheckWindowedBAWindow). The window's
  // pyramids must outlive the returned problem.
  virtual WindowedBAProblem Build(const WindowedBAWindow& window) const = 0;
};

using WindowedBAProblemBuilderFactory =
    std::function<std::unique_ptr<WindowedBAProblemBuilder>(const WindowedBAOptions&)>;

// name -> factory of every windowed BA builder, constructed on each call:
//   "windowed_ba"             the residuals above, robust loss row-wise inside the cost functions
//                             (each pattern pixel keeps its own robustness, as tracking);
//   "windowed_ba_ceres_loss"  the same rows, the loss given to the problem per residual block (a
//                             point's pattern in one target, or one line row), as DSO
//                             robustifies per point; the solvers apply Triggs' correction.
std::map<std::string, WindowedBAProblemBuilderFactory> WindowedBAProblemBuilderRegistry();
// Throws std::invalid_argument listing the known names when `name` is unknown, or when the
// options are invalid.
std::unique_ptr<WindowedBAProblemBuilder> MakeWindowedBAProblemBuilder(
    const std::string& name, const WindowedBAOptions& options);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_WINDOWED_BA_WINDOWED_BA_PROBLEM_BUILDER_H_
