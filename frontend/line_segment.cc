#include "frontend/line_segment.h"

#include <cmath>

#include "residuals/covariance_models.h"

namespace pldvo {

LineSegment MakeLineSegment(const Eigen::Vector2d& start, const Eigen::Vector2d& end, int octave,
                            double sigma_px) {
  const LineWithCovariance fitted = FitLine(start, end, sigma_px);
  LineSegment segment;
  segment.start = start;
  segment.end = end;
  segment.octave = octave;
  segment.length = (end - start).norm();
  segment.angle = std::atan2(end.y() - start.y(), end.x() - start.x());
  segment.line = fitted.line;
  segment.line_cov = fitted.cov;
  return segment;
}

double AngleDifference(double angle_a, double angle_b) {
  double diff = std::fmod(std::abs(angle_a - angle_b), 2.0 * M_PI);
  return diff > M_PI ? 2.0 * M_PI - diff : diff;
}

}  // namespace pldvo
