// The image line segment every part of the line frontend exchanges.
//
// Conventions: pixel coordinates at full resolution (octave 0), integer coordinates at pixel
// centres as in core/pinhole_camera.h. A segment is directed: d = (end - start) / length, and
// its normal n = (-d_y, d_x) points towards the brighter side (the line detector orients every
// segment so that the image gradient across it has a positive component along n; LBD uses
// the same frame, so descriptors of the same edge agree between frames and opposite-polarity
// edges never match).
// Line coefficients l = (a, b, c) = (n_x, n_y, -n . start) with a^2 + b^2 = 1, so that
// l^T (u, v, 1) is the signed distance in pixels (the convention of FitLine in
// residuals/covariance_models.h, whose first-order Sigma_l we store with each segment).
#ifndef PLDVO_FRONTEND_LINE_SEGMENT_H_
#define PLDVO_FRONTEND_LINE_SEGMENT_H_

#include <Eigen/Core>

namespace pldvo {

struct LineSegment {
  Eigen::Vector2d start = Eigen::Vector2d::Zero();  // full-resolution pixels
  Eigen::Vector2d end = Eigen::Vector2d::Zero();
  // Octave the segment was detected on (or the finest octave among merged parts): 0 full
  // resolution, k the image downsampled by 2^k.
  int octave = 0;
  double length = 0.0;                                 // |end - start| in pixels
  double angle = 0.0;                                  // atan2(d_y, d_x) in (-pi, pi]
  Eigen::Vector3d line = Eigen::Vector3d::Zero();      // l = (a, b, c), a^2 + b^2 = 1
  Eigen::Matrix3d line_cov = Eigen::Matrix3d::Zero();  // Sigma_l (rank 2)

  Eigen::Vector2d direction() const { return (end - start) / length; }
  Eigen::Vector2d normal() const { return line.head<2>(); }
  Eigen::Vector2d midpoint() const { return 0.5 * (start + end); }
  // Signed distance l^T (p; 1) of a pixel to the infinite line.
  double SignedDistance(const Eigen::Vector2d& p) const {
    return line.x() * p.x() + line.y() * p.y() + line.z();
  }
  // Coordinate of p along the segment: 0 at start, length at end.
  double Project(const Eigen::Vector2d& p) const { return direction().dot(p - start); }
};

// A segment from its endpoints; fills length, angle, l and Sigma_l, the latter for isotropic
// endpoint noise of standard deviation sigma_px (FitLine, residuals/covariance_models.h).
// Throws std::invalid_argument when the endpoints coincide or sigma_px < 0.
LineSegment MakeLineSegment(const Eigen::Vector2d& start, const Eigen::Vector2d& end, int octave,
                            double sigma_px);

// Smallest absolute difference of two directed angles (radians), in [0, pi].
double AngleDifference(double angle_a, double angle_b);

}  // namespace pldvo

#endif  // PLDVO_FRONTEND_LINE_SEGMENT_H_
