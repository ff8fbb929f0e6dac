#include "backend/mapping/line_regularizer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace pldvo {
namespace {

// The map index of traced pixel p when it lies in the map and holds a valid hypothesis, else -1.
int ValidIndex(const SemiDenseDepthMap& map, const Eigen::Vector2i& p) {
  if (p.x() < 0 || p.y() < 0 || p.x() >= map.width() || p.y() >= map.height()) return -1;
  const int index = map.Index(p.x(), p.y());
  return map.valid(index) ? index : -1;
}

// Weighted least squares of d = x^T c over the selected samples; false when degenerate.
bool SolveWeighted(const std::vector<Eigen::Vector2d>& rays, const std::vector<double>& idepths,
                   const std::vector<double>& vars, const std::vector<uint8_t>& use,
                   Eigen::Vector2d* coeffs, Eigen::Matrix2d* cov) {
  Eigen::Matrix2d h = Eigen::Matrix2d::Zero();
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!use[i]) continue;
    const double w = 1.0 / vars[i];
    h += w * rays[i] * rays[i].transpose();
    g += w * idepths[i] * rays[i];
  }
  // Relative conditioning: the rays of a short edge are nearly parallel.
  const double det = h.determinant();
  if (!(det > 1e-12 * h.trace() * h.trace())) return false;
  *cov = h.inverse();
  *coeffs = *cov * g;
  return true;
}

int SelectInliers(const std::vector<Eigen::Vector2d>& rays, const std::vector<double>& idepths,
                  const std::vector<double>& vars, const std::vector<uint8_t>& valid,
                  const Eigen::Vector2d& coeffs, double gate, std::vector<uint8_t>* inlier,
                  double* chi2_sum) {
  int count = 0;
  double sum = 0.0;
  for (size_t i = 0; i < rays.size(); ++i) {
    (*inlier)[i] = 0;
    if (!valid[i]) continue;
    const double r = idepths[i] - rays[i].dot(coeffs);
    const double m2 = r * r / vars[i];
    if (m2 < gate) {
      (*inlier)[i] = 1;
      ++count;
      sum += m2;
    }
  }
  if (chi2_sum) *chi2_sum = sum;
  return count;
}

// ---- The paper's variant (eqs. 11-13; LineRegularizer header).

// A point of the edge plane F with its uncertainty along its viewing ray.
struct PlanePoint {
  Eigen::Vector2d position;  // (X_i, Y_i) = (a_i, b_i) / d_i
  Eigen::Vector2d ray;       // unit in-plane direction of the ray, (a_i, b_i) / |(a_i, b_i)|
  double range_var = 0.0;    // variance along the ray: |(a_i, b_i)|^2 V_i / d_i^4
};

// Line m^T P = offset with |m| = 1, from Y = beta0 + beta1 X.
void LineFromBeta(const Eigen::Vector2d& beta, Eigen::Vector2d* normal, double* offset) {
  const double norm = std::sqrt(1.0 + beta[1] * beta[1]);
  *normal = Eigen::Vector2d(-beta[1], 1.0) / norm;
  *offset = beta[0] / norm;
}

// Eq. 12: the 2-D Mahalanobis distance of point i to the line m^T P = offset. With the point's
// covariance Sigma_i = range_var u u^T (rank 1, along the ray u) the minimum over the line's
// points of the Mahalanobis distance is (m^T P_i - offset)^2 / (m^T Sigma_i m); infinite when
// the ray runs along the line.
double PlaneMahalanobis2(const PlanePoint& point, const Eigen::Vector2d& normal, double offset) {
  const double r = normal.dot(point.position) - offset;
  const double cos_ray = normal.dot(point.ray);
  const double var = point.range_var * cos_ray * cos_ray;
  if (!(var > 0.0)) return std::numeric_limits<double>::infinity();
  return r * r / var;
}

int SelectPlaneInliers(const std::vector<PlanePoint>& points, const std::vector<uint8_t>& valid,
                       const Eigen::Vector2d& normal, double offset, double gate,
                       std::vector<uint8_t>* inlier, double* chi2_sum) {
  int count = 0;
  double sum = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    (*inlier)[i] = 0;
    if (!valid[i]) continue;
    const double m2 = PlaneMahalanobis2(points[i], normal, offset);
    if (m2 < gate) {
      (*inlier)[i] = 1;
      ++count;
      sum += m2;
    }
  }
  if (chi2_sum) *chi2_sum = sum;
  return count;
}

// Eq. 13: the closed-form least-squares line Y = X beta, X rows (1, X_i), Y_i the points' Y, over
// the selected points; Cov(beta) = s^2 (X^T X)^-1 with s^2 the residual variance. False when
// degenerate (fewer than 3 points or X^T X ill-conditioned).
bool SolveBeta(const std::vector<PlanePoint>& points, const std::vector<uint8_t>& use,
               Eigen::Vector2d* beta, Eigen::Matrix2d* beta_cov) {
  Eigen::Matrix2d xtx = Eigen::Matrix2d::Zero();
  Eigen::Vector2d xty = Eigen::Vector2d::Zero();
  int n = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) continue;
    const Eigen::Vector2d row(1.0, points[i].position.x());
    xtx += row * row.transpose();
    xty += row * points[i].position.y();
    ++n;
  }
  if (n < 3) return false;
  const double det = xtx.determinant();
  if (!(det > 1e-12 * xtx.trace() * xtx.trace())) return false;
  const Eigen::Matrix2d xtx_inv = xtx.inverse();
  *beta = xtx_inv * xty;
  double rss = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) continue;
    const double r = points[i].position.y() - (*beta)[0] - (*beta)[1] * points[i].position.x();
    rss += r * r;
  }
  *beta_cov = rss / (n - 2) * xtx_inv;
  return true;
}

}  // namespace

Eigen::Vector3d LineFit::PointInRef() const {
  // Nearest point of c^T p = 1 to the origin: p = c / |c|^2.
  const Eigen::Vector2d p = coeffs / coeffs.squaredNorm();
  return p.x() * e_x + p.y() * e_y;
}

Eigen::Vector3d LineFit::DirectionInRef() const {
  const Eigen::Vector2d d = Eigen::Vector2d(-coeffs.y(), coeffs.x()).normalized();
  return d.x() * e_x + d.y() * e_y;
}

LineRegularizer::LineRegularizer(const MappingOptions& options) : options_(options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument(error);
}

LineFit LineRegularizer::FitEdge(const PinholeCamera& camera, const Eigen::Vector3d& line_in_ref,
                                 const std::vector<Eigen::Vector2i>& pixels,
                                 const SemiDenseDepthMap& map, std::mt19937* rng) const {
  LineFit fit;
  const size_t n = pixels.size();
  fit.inlier.assign(n, 0);
  const Eigen::Vector3d normal_unscaled = camera.K().transpose() * line_in_ref;
  if (!(normal_unscaled.norm() > 0.0)) return fit;
  fit.normal = normal_unscaled.normalized();

  std::vector<Eigen::Vector3d> rays3(n);
  std::vector<uint8_t> valid(n, 0);
  std::vector<double> idepths(n, 0.0), vars(n, 1.0);
  std::vector<int> valid_index;
  valid_index.reserve(n);
  Eigen::Vector3d mean_ray = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2i& p = pixels[i];
    rays3[i] = camera.Unproject(p.cast<double>());
    mean_ray += rays3[i].normalized();
    if (p.x() < 0 || p.y() < 0 || p.x() >= map.width() || p.y() >= map.height()) continue;
    const int index = map.Index(p.x(), p.y());
    if (!map.valid(index) || !(map.idepth_var(index) > 0.f)) continue;
    valid[i] = 1;
    idepths[i] = map.idepth(index);
    vars[i] = map.idepth_var(index);
    valid_index.push_back(static_cast<int>(i));
  }
  fit.num_used = static_cast<int>(valid_index.size());
  if (fit.num_used < options_.line_min_pixels) return fit;
  Eigen::Vector3d e_y = mean_ray - mean_ray.dot(fit.normal) * fit.normal;
  if (!(e_y.norm() > 1e-9)) return fit;
  fit.e_y = e_y.normalized();
  fit.e_x = fit.e_y.cross(fit.normal);
  std::vector<Eigen::Vector2d> rays(n);
  for (size_t i = 0; i < n; ++i)
    rays[i] = Eigen::Vector2d(fit.e_x.dot(rays3[i]), fit.e_y.dot(rays3[i]));

  if (options_.line_regularization_method == MappingOptions::LineRegularizationMethod::kPaper2d) {
    FitPaper2d(rays, idepths, vars, valid, valid_index, rng, &fit);
    return fit;
  }

  // RANSAC over pairs of valid pixels.
  const double gate = options_.line_ransac_gate_chi2;
  std::uniform_int_distribution<int> pick(0, fit.num_used - 1);
  std::vector<uint8_t> inlier(n, 0);
  int best_count = -1;
  double best_chi2 = 0.0;
  Eigen::Vector2d best_coeffs = Eigen::Vector2d::Zero();
  for (int iteration = 0; iteration < options_.line_ransac_iterations; ++iteration) {
    const int i = valid_index[pick(*rng)], j = valid_index[pick(*rng)];
    if (i == j) continue;
    Eigen::Matrix2d a;
    a.row(0) = rays[i].transpose();
    a.row(1) = rays[j].transpose();
    if (!(std::abs(a.determinant()) > 1e-12 * a.squaredNorm())) continue;
    const Eigen::Vector2d coeffs = a.inverse() * Eigen::Vector2d(idepths[i], idepths[j]);
    double chi2 = 0.0;
    const int count = SelectInliers(rays, idepths, vars, valid, coeffs, gate, &inlier, &chi2);
    if (count > best_count || (count == best_count && chi2 < best_chi2)) {
      best_count = count;
      best_chi2 = chi2;
      best_coeffs = coeffs;
    }
  }
  if (best_count < 2) return fit;
  Eigen::Vector2d coeffs = best_coeffs;
  Eigen::Matrix2d cov;
  for (int refit = 0; refit < 2; ++refit) {
    SelectInliers(rays, idepths, vars, valid, coeffs, gate, &inlier, nullptr);
    if (!SolveWeighted(rays, idepths, vars, inlier, &coeffs, &cov)) return fit;
  }
  fit.num_inliers = SelectInliers(rays, idepths, vars, valid, coeffs, gate, &inlier, nullptr);
  const int min_inliers =
      std::max(options_.line_min_pixels,
               static_cast<int>(std::ceil(options_.line_min_inlier_ratio * fit.num_used)));
  if (fit.num_inliers < min_inliers) return fit;
  fit.ok = true;
  fit.coeffs = coeffs;
  fit.cov = cov;
  fit.inlier = inlier;
  return fit;
}

void LineRegularizer::FitPaper2d(const std::vector<Eigen::Vector2d>& rays,
                                 const std::vector<double>& idepths,
                                 const std::vector<double>& vars, std::vector<uint8_t> valid,
                                 const std::vector<int>& valid_index, std::mt19937* rng,
                                 LineFit* fit) const {
  // Eq. 11: the pixels' 3D points in F; points at infinity (d <= 0) cannot enter the fit.
  const size_t n = rays.size();
  std::vector<PlanePoint> points(n);
  std::vector<int> usable;
  for (int i : valid_index) {
    const double norm = rays[i].norm();
    if (!(idepths[i] > 1e-6) || !(norm > 0.0)) {
      valid[i] = 0;
      continue;
    }
    points[i].position = rays[i] / idepths[i];
    points[i].ray = rays[i] / norm;
    points[i].range_var = norm * norm * vars[i] / std::pow(idepths[i], 4);
    usable.push_back(i);
  }
  if (static_cast<int>(usable.size()) < options_.line_min_pixels) return;
  // RANSAC over pairs of points, scored by the inliers of eq. 12.
  const double gate = options_.line_ransac_gate_chi2;
  std::uniform_int_distribution<int> pick(0, static_cast<int>(usable.size()) - 1);
  std::vector<uint8_t> inlier(n, 0);
  int best_count = -1;
  double best_chi2 = 0.0;
  Eigen::Vector2d best_normal = Eigen::Vector2d::Zero();
  double best_offset = 0.0;
  for (int iteration = 0; iteration < options_.line_ransac_iterations; ++iteration) {
    const int i = usable[pick(*rng)], j = usable[pick(*rng)];
    if (i == j) continue;
    const Eigen::Vector2d direction = points[j].position - points[i].position;
    if (!(direction.norm() > 1e-9)) continue;
    const Eigen::Vector2d normal = Eigen::Vector2d(-direction.y(), direction.x()).normalized();
    const double offset = normal.dot(points[i].position);
    double chi2 = 0.0;
    const int count = SelectPlaneInliers(points, valid, normal, offset, gate, &inlier, &chi2);
    if (count > best_count || (count == best_count && chi2 < best_chi2)) {
      best_count = count;
      best_chi2 = chi2;
      best_normal = normal;
      best_offset = offset;
    }
  }
  if (best_count < 3) return;
  // Eq. 13 on the inliers, then once more on the refitted line's inliers.
  Eigen::Vector2d normal = best_normal, beta;
  double offset = best_offset;
  Eigen::Matrix2d beta_cov;
  for (int refit = 0; refit < 2; ++refit) {
    SelectPlaneInliers(points, valid, normal, offset, gate, &inlier, nullptr);
    if (!SolveBeta(points, inlier, &beta, &beta_cov)) return;
    LineFromBeta(beta, &normal, &offset);
  }
  // A line through the centre has no inverse-depth form c1 X + c2 Y = 1.
  if (!(std::abs(beta[0]) > 1e-9)) return;
  fit->num_inliers = SelectPlaneInliers(points, valid, normal, offset, gate, &inlier, nullptr);
  const int min_inliers =
      std::max(options_.line_min_pixels,
               static_cast<int>(std::ceil(options_.line_min_inlier_ratio * fit->num_used)));
  if (fit->num_inliers < min_inliers) return;
  // Y = beta0 + beta1 X is c1 X + c2 Y = 1 with c = (-beta1 / beta0, 1 / beta0); Cov(c) by the
  // Jacobian of that map.
  Eigen::Matrix2d jacobian;
  jacobian << beta[1] / (beta[0] * beta[0]), -1.0 / beta[0], -1.0 / (beta[0] * beta[0]), 0.0;
  fit->ok = true;
  fit->coeffs = Eigen::Vector2d(-beta[1] / beta[0], 1.0 / beta[0]);
  fit->cov = jacobian * beta_cov * jacobian.transpose();
  fit->inlier = inlier;
}

void LineRegularizer::FitEdges(
    const PinholeCamera& camera, const EdgeTrace& edges, const SemiDenseDepthMap& map,
    const std::function<void(const TracedLine&, const LineFit&)>& on_edge) const {
  std::mt19937 rng(static_cast<uint32_t>(options_.line_ransac_seed));
  for (const TracedLine& edge : edges.lines) {
    if (edge.pixels.empty()) continue;
    on_edge(edge, FitEdge(camera, edge.segment.line, edge.pixels, map, &rng));
  }
}

LineRegularizationStats LineRegularizer::Regularize(const PinholeCamera& camera,
                                                    const EdgeTrace& edges,
                                                    SemiDenseDepthMap* map) const {
  LineRegularizationStats stats;
  FitEdges(camera, edges, *map, [&](const TracedLine& edge, const LineFit& fit) {
    if (!fit.ok) {
      if (fit.num_used > 0) ++stats.edges_rejected;
      return;
    }
    ++stats.edges_fitted;
    for (size_t i = 0; i < edge.pixels.size(); ++i) {
      const int index = ValidIndex(*map, edge.pixels[i]);
      if (index < 0) continue;
      if (!fit.inlier[i]) {
        ++stats.pixels_rejected;
        continue;
      }
      const Eigen::Vector3d ray = camera.Unproject(edge.pixels[i].cast<double>());
      const Eigen::Vector2d x(fit.e_x.dot(ray), fit.e_y.dot(ray));
      const double idepth = x.dot(fit.coeffs);
      if (!(idepth > 0.0)) continue;
      // Conservative variance (see the header): the fully-correlated bound N x^T Cov(c) x, never
      // above the pixel's own variance.
      const double var =
          std::min<double>(map->idepth_var(index), fit.num_inliers * x.dot(fit.cov * x));
      map->SetIdepthAndVar(index, idepth, var);
      ++stats.pixels_updated;
    }
  });
  return stats;
}

LineRegularizationStats LineRegularizer::UnlinkOutliers(const PinholeCamera& camera,
                                                        const EdgeTrace& edges,
                                                        SemiDenseDepthMap* map) const {
  LineRegularizationStats stats;
  FitEdges(camera, edges, *map, [&](const TracedLine& edge, const LineFit& fit) {
    if (fit.ok) {
      ++stats.edges_fitted;
    } else if (fit.num_used >= options_.line_min_pixels) {
      ++stats.edges_rejected;
    } else {
      return;  // too few depths to judge: the edge keeps its pixels
    }
    for (size_t i = 0; i < edge.pixels.size(); ++i) {
      const int index = ValidIndex(*map, edge.pixels[i]);
      if (index < 0 || map->edge_id(index) != edge.id || (fit.ok && fit.inlier[i])) continue;
      map->SetCandidate(index, map->candidate(index), -1);
      ++stats.pixels_unlinked;
    }
  });
  return stats;
}

}  // namespace pldvo
