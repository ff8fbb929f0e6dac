// 3D line regularisation of edge pixels (Yang & Scherer, ICRA 2017, Sec. V-B): the pixels of a
// straight image edge back-project to points of one 3D line, so their inverse depths are refit
// jointly.
//
// Frame F (eq. 11): the plane through the keyframe centre and the edge has the normal
// n = K^T l1 / |K^T l1| (l1 the edge's keyframe line). F has its origin at the centre, e_y the
// mean viewing ray of the edge projected into the plane, e_x = e_y x n. A pixel x_i with ray
// r_i = K^-1 (x_i; 1) and inverse depth d_i is the point P_i = r_i / d_i with F coordinates
// (X_i, Y_i) = (a_i, b_i) / d_i, (a_i, b_i) = (e_x . r_i, e_y . r_i) (the ray's in-plane part;
// the component along n, at most the pixel's distance to l1, is dropped).
//
// Line model: a 2D line of F not through the centre is c1 X + c2 Y = 1 (equivalently the
// paper's Y = beta0 + beta1 X with beta0 = 1/c2, beta1 = -c1/c2). Along the ray of pixel i it
// predicts d_i = c1 a_i + c2 b_i: linear in c, and the pixel's noise lives along its ray, i.e. in
// d_i with variance V_i. Hence
//   Mahalanobis distance (1-D, for eq. 12):  m_i^2 = (d_i - x_i^T c)^2 / V_i,  x_i = (a_i, b_i),
//   weighted least squares (for eq. 13): c = (X^T W X)^-1 X^T W Y,  X rows x_i^T, Y_i = d_i,
//                                    W = diag(1 / V_i),   Cov(c) = (X^T W X)^-1,
// exact with the true inverse variances as weights (no iteration). RANSAC draws two pixels,
// solves for c, counts inliers with m_i^2 < gate, then refits on the inliers (twice: the
// refined line re-selects its inliers once).
//
// Update: every inlier pixel gets the line's prediction d_i' = x_i^T c. This replaces, not fuses,
// the pixel's estimate: the line was computed from it, so a product with the old Gaussian would
// count the same data twice. Outliers keep their values. Variance: x_i^T Cov(c) x_i is the
// variance of the fitted line at pixel i only if the pixels' errors are independent; along an
// edge they are not (line-guided pixels share the matched line's error, photometric pixels
// overlapping SSD patches), and with x_i^T Cov(c) x_i (~ V / N) the measured NEES of the
// regularised pixels was 20-70 (docs/mapping.md). We therefore use the fully-correlated bound
//   V_i' = min(V_i, N_inliers x_i^T Cov(c) x_i)
// (if all N errors were identical the fit would be as uncertain as one pixel), which never
// claims more certainty than the pixel had. The regularisation is applied to a copy of the filter
// state (DepthMapper::RegularizedMap), never fed back into the EKF.
//
// The above is MappingOptions::LineRegularizationMethod::kRay1d (the default). kPaper2d follows
// the paper's eqs. 11-13 as published: each valid pixel is the point P_i = (a_i, b_i) / d_i of F
// (eq. 11) with the covariance of its inverse depth mapped along its ray, Sigma_i = s_i^2 u_i
// u_i^T (u_i the unit in-plane ray, s_i^2 = |(a_i, b_i)|^2 V_i / d_i^4); RANSAC draws two points,
// takes the line through them and counts the points whose 2-D Mahalanobis distance to it
// (eq. 12; for a rank-1 Sigma_i, (m^T P_i - o)^2 / (m^T Sigma_i m) with m^T P = o the line) is
// below the gate; the inliers are then fitted by the closed-form least squares Y = X beta (eq.
// 13; X rows (1, X_i), Y_i the points' Y, unweighted), twice as above. The result is written in
// the same form c = (-beta1 / beta0, 1 / beta0) with Cov(c) from s^2 (X^T X)^-1 (s^2 the residual
// variance), and Regularize updates the inliers as for kRay1d.
#ifndef PLDVO_BACKEND_MAPPING_LINE_REGULARIZER_H_
#define PLDVO_BACKEND_MAPPING_LINE_REGULARIZER_H_

#include <Eigen/Core>
#include <functional>
#include <random>
#include <vector>

#include "backend/mapping/mapping_options.h"
#include "backend/mapping/semi_dense_depth_map.h"
#include "core/pinhole_camera.h"
#include "frontend/edge_tracer.h"

namespace pldvo {

// The fit of one edge.
struct LineFit {
  bool ok = false;
  Eigen::Vector2d coeffs = Eigen::Vector2d::Zero();  // c: c1 X + c2 Y = 1 in F
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();     // Cov(c) = (X^T W X)^-1
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // plane normal n (keyframe frame)
  Eigen::Vector3d e_x = Eigen::Vector3d::Zero();     // F's axes in the keyframe frame
  Eigen::Vector3d e_y = Eigen::Vector3d::Zero();
  int num_used = 0;  // valid pixels the fit saw
  int num_inliers = 0;
  std::vector<uint8_t> inlier;  // per input pixel (0 also for invalid pixels)

  // The fitted 3D line in the keyframe frame: the point nearest the centre and the direction.
  Eigen::Vector3d PointInRef() const;
  Eigen::Vector3d DirectionInRef() const;
};

struct LineRegularizationStats {
  int edges_fitted = 0;
  int edges_rejected = 0;  // too few valid pixels or inliers, or degenerate
  int pixels_updated = 0;
  int pixels_rejected = 0;  // outliers of fitted edges
  int pixels_unlinked = 0;  // UnlinkOutliers: valid pixels taken off their edge
};

class LineRegularizer {
 public:
  // Throws std::invalid_argument when options.Check() fails.
  explicit LineRegularizer(const MappingOptions& options);

  // Fits the edge with keyframe line `line_in_ref` (l1, a^2 + b^2 = 1) through `pixels` using the
  // valid hypotheses of `map`.
  LineFit FitEdge(const PinholeCamera& camera, const Eigen::Vector3d& line_in_ref,
                  const std::vector<Eigen::Vector2i>& pixels, const SemiDenseDepthMap& map,
                  std::mt19937* rng) const;

  // Fits every traced edge and updates its inliers in `map` (see the header comment).
  LineRegularizationStats Regularize(const PinholeCamera& camera, const EdgeTrace& edges,
                                     SemiDenseDepthMap* map) const;

  // MappingOptions::line_depth_gate: fits every traced edge as Regularize does and takes the
  // valid pixels the fit rejects off their edge (edge id -1, depths unchanged); an edge whose
  // fit fails with at least line_min_pixels valid pixels loses all of them.
  LineRegularizationStats UnlinkOutliers(const PinholeCamera& camera, const EdgeTrace& edges,
                                         SemiDenseDepthMap* map) const;

 private:
  // Fits every traced edge with pixels, in order, with one RANSAC stream seeded by
  // line_ransac_seed, and hands each fit to on_edge (which may change `map` for later edges).
  void FitEdges(const PinholeCamera& camera, const EdgeTrace& edges, const SemiDenseDepthMap& map,
                const std::function<void(const TracedLine&, const LineFit&)>& on_edge) const;

  // The paper's fit (eqs. 11-13) of the valid pixels with in-plane rays `rays`; fills *fit.
  void FitPaper2d(const std::vector<Eigen::Vector2d>& rays, const std::vector<double>& idepths,
                  const std::vector<double>& vars, std::vector<uint8_t> valid,
                  const std::vector<int>& valid_index, std::mt19937* rng, LineFit* fit) const;

  MappingOptions options_;
};

}  // namespace pldvo

#endif  // PLDVO_BACKEND_MAPPING_LINE_REGULARIZER_H_
