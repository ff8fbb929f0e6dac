// Problem builders turn a tracking reference and a current image pyramid into the
// LeastSquaresProblem of one pyramid level, with every weight (sqrt_info) computed at the
// linearisation point (the pose block's value when Build is called) and held constant during
// the solve. They are registered by name (config `tracking.problem_builder`); the registry is a
// map built explicitly by ProblemBuilderRegistry(), no mutable global state.
//
// Registered builders (tracking_problem_builder.h):
//   "tracking"             photometric (eq. 2) and point-to-line (eq. 3) blocks as the
//                          weighting policy says, `batch_size` pixels per residual block, robust
//                          loss row-wise inside the cost functions, the current image sampled
//                          with `interpolation`.
//   "tracking_ceres_loss"  the same residuals with one block per pixel and the robust loss given
//                          to the problem as a ceres::LossFunction (the per-pixel layout of the
//                          issue; the Gauss-Newton solver applies the Triggs correction).
#ifndef PLDVO_BACKEND_TRACKING_PROBLEM_BUILDER_H_
#define PLDVO_BACKEND_TRACKING_PROBLEM_BUILDER_H_

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "backend/optimization/least_squares_problem.h"
#include "backend/tracking/tracking_reference.h"
#include "core/image_pyramid.h"
#include "core/options.h"
#include "residuals/affine_brightness.h"
#include "residuals/photometric_residual.h"
#include "residuals/weighting.h"

namespace pldvo {

struct ProblemBuilderOptions {
  // Pixels per residual block. Batching amortises Ceres' per-block overhead; the robust loss is
  // row-wise inside the cost functions, so a batch keeps per-pixel robustness. 128 measured as
  // fast as larger batches (docs/tracking.md, "Timing").
  int batch_size = 128;
  // Sampling of the current image in the photometric residual (residuals/photometric_residual.h):
  // bilinear (C0 cost, interpolated central-difference gradient) or bicubic (Keys / Catmull-Rom,
  // C1 cost, exact derivative as gradient). Measurements: docs/tracking.md.
  ImageInterpolation interpolation = ImageInterpolation::kBilinear;
  // Brightness transfer estimated with the pose (residuals/affine_brightness.h): none (the
  // semi-dense VO's I_ref - I_cur) or affine (DSO's model I_cur ~ e^a I_ref + b, in the
  // symmetric residual of residuals/photometric_residual.h), with a weak zero-mean prior of
  // these standard deviations on a and b: the change of exposure expected between a keyframe
  // and its frames, about +-10% and +-10 gray levels (docs/tracking.md, "Affine brightness":
  // with 0.5 / 50 the pair drifts along its degenerate direction on KITTI).
  BrightnessModel brightness = BrightnessModel::kNone;
  double brightness_prior_sigma_a = 0.1;
  double brightness_prior_sigma_b = 10.0;
  // The photometric rows of one keyframe edge (reference points with one edge id) count as at
  // most this many points: an edge with n > max_rows_per_edge rows at a level has each row's
  // weight scaled by sqrt(max_rows_per_edge / n), so its total information is that of
  // max_rows_per_edge points. The points of an edge share its errors (a depth wrong along the
  // whole edge, an occluding edge that splits): hundreds of coherent rows otherwise outvote the
  // rest of the view through a row-wise robust loss (docs/tracking.md, "Rows per edge"). 0: off
  // (paper.yaml); 50 measured as 20 on the development set (both 0.85x the RPE without).
  double max_rows_per_edge = 50.0;
  // The same cap on the point-to-line rows of one keyframe edge (eq. 3): its pixels share the
  // matched line's detection error and the edge's depth error. 0: off. Per-pixel line error
  // model only (shared_per_edge already whitens an edge's rows together).
  double max_line_rows_per_edge = 0.0;
  // The point-to-line rows enter the levels >= this one only: coarser levels widen the basin
  // with them, finer ones are solved on the photometric rows alone. 0: every level.
  int line_finest_level = 0;
  WeightingOptions weighting;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    v.Field("batch_size", &batch_size, "Pixels per residual block (1 = one block per pixel).");
    v.Choice("interpolation", &interpolation, ImageInterpolationNames(),
             "Photometric sampling of the current image: bilinear (C0 cost) or bicubic (C1 "
             "cost, exact Jacobian).");
    v.Choice("brightness", &brightness, BrightnessModelNames(),
             "Brightness transfer estimated with the pose: none (I_ref - I_cur) or affine "
             "(I_cur ~ e^a I_ref + b; residual e^(-a/2) (e^a I_ref + b - I_cur)).");
    v.Field("brightness_prior_sigma_a", &brightness_prior_sigma_a,
            "Standard deviation of the zero-mean prior on the log-gain a (affine).");
    v.Field("brightness_prior_sigma_b", &brightness_prior_sigma_b,
            "Standard deviation of the zero-mean prior on the bias b, gray levels (affine).");
    v.Field("max_rows_per_edge", &max_rows_per_edge,
            "Photometric rows of one keyframe edge count as at most this many points (each "
            "row's weight scaled by sqrt(cap / n)); 0 = off (default 50).");
    v.Field("max_line_rows_per_edge", &max_line_rows_per_edge,
            "Point-to-line rows of one keyframe edge count as at most this many points (each "
            "row's weight scaled by sqrt(cap / n)); 0 = off (default 0).");
    v.Field("line_finest_level", &line_finest_level,
            "Point-to-line rows only at pyramid levels >= this one (0 = every level).");
    v.Section("weighting", &weighting, "Weighting of the residual families and robust loss.");
  }
  std::string Check() const;
};

// What one Build added.
struct BuildStatistics {
  int photometric_residuals = 0;  // rows
  int line_residuals = 0;         // rows
  int residual_blocks = 0;
};

class ProblemBuilder {
 public:
  virtual ~ProblemBuilder() = default;
  // Adds `cur_from_ref` (double[7], SE3Manifold) as a parameter block if `problem` does not
  // have it yet (and with brightness affine `brightness`, double[2] = {a, b}; ignored with
  // none), then the residual blocks of `level`, weighted at the pose it currently holds.
  // `reference` and `current` must outlive `problem`. Throws std::invalid_argument when the
  // level exists in neither, or when affine brightness gets no block.
  virtual BuildStatistics Build(const TrackingReference& reference, const ImagePyramid& current,
                                int level, double* cur_from_ref, double* brightness,
                                LeastSquaresProblem* problem) const = 0;
};

using ProblemBuilderFactory =
    std::function<std::unique_ptr<ProblemBuilder>(const ProblemBuilderOptions&)>;

// name -> factory of every builder, constructed on each call.
std::map<std::string, ProblemBuilderFactory> ProblemBuilderRegistry();
// Throws std::invalid_argument listing the known names when `name` is unknown, or when the
// options are invalid.
std::unique_ptr<ProblemBuilder> MakeProblemBuilder(const std::string& name,
                                                   const ProblemBuilderOptions& options);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_TRACKING_PROBLEM_BUILDER_H_
