#include "backend/mapping/depth_propagation.h"

#include <cmath>
#include <stdexcept>

namespace pldvo {

SemiDenseDepthMap PropagateDepthMap(const SemiDenseDepthMap& old_map,
                                    const ImagePyramid& old_keyframe,
                                    const ImagePyramid& new_keyframe,
                                    const cv::Mat& new_edge_id_map, const PinholeCamera& camera,
                                    const SE3& new_from_old, const MappingOptions& options,
                                    PropagationStats* stats,
                                    const AffineBrightness& new_from_old_brightness) {
  if (old_keyframe.num_levels() < 1 || old_keyframe.width(0) != old_map.width() ||
      old_keyframe.height(0) != old_map.height() || new_keyframe.num_levels() < 1) {
    throw std::invalid_argument("PropagateDepthMap: keyframe and map sizes differ");
  }
  PropagationStats local;
  PropagationStats& s = stats ? *stats : local;
  s = PropagationStats();
  SemiDenseDepthMap new_map(new_keyframe.width(0), new_keyframe.height(0));
  const double inverse_gain = std::exp(-new_from_old_brightness.a);
  new_map.SelectPixels(new_keyframe, new_edge_id_map, options);
  const Eigen::Matrix3d rotation = new_from_old.rotation_matrix();
  const Eigen::Vector3d& translation = new_from_old.translation();
  const double gate_sq = options.outlier_gate_sigmas * options.outlier_gate_sigmas;
  const int border = options.border_px;
  for (int y = 0; y < old_map.height(); ++y) {
    for (int x = 0; x < old_map.width(); ++x) {
      const int i = old_map.Index(x, y);
      if (!old_map.valid(i)) continue;
      const double d0 = old_map.idepth(i);
      if (!(d0 > 0.0)) continue;
      const Eigen::Vector3d ray_rotated = rotation * camera.Unproject(Eigen::Vector2d(x, y));
      const Eigen::Vector3d point = ray_rotated / d0 + translation;
      if (!(point.z() > 1e-6)) {
        ++s.dropped_outside;
        continue;
      }
      const Eigen::Vector2d pixel = camera.Project(point);
      const int u = static_cast<int>(std::lround(pixel.x()));
      const int v = static_cast<int>(std::lround(pixel.y()));
      if (u < border || v < border || u >= new_map.width() - border ||
          v >= new_map.height() - border) {
        ++s.dropped_outside;
        continue;
      }
      const int j = new_map.Index(u, v);
      if (!new_map.candidate(j)) {
        ++s.dropped_not_candidate;
        continue;
      }
      const double intensity_old = old_keyframe.level(0).ptr<float>(y)[3 * x];
      const double intensity_new =
          inverse_gain *
          (new_keyframe.SampleIntensity(0, pixel.x(), pixel.y()) - new_from_old_brightness.b);
      if (std::abs(intensity_new - intensity_old) > options.max_propagation_intensity_diff) {
        ++s.dropped_intensity;
        continue;
      }
      const double d1 = 1.0 / point.z();
      const double jacobian = ray_rotated.z() * d1 * d1 / (d0 * d0);
      const double v1 = jacobian * jacobian * old_map.idepth_var(i) + options.propagation_var;
      if (new_map.valid(j)) {
        const double d_other = new_map.idepth(j), v_other = new_map.idepth_var(j);
        if ((d1 - d_other) * (d1 - d_other) <= gate_sq * (v1 + v_other)) {
          const double sum = v1 + v_other;
          new_map.SetIdepthAndVar(j, (v_other * d1 + v1 * d_other) / sum, v1 * v_other / sum);
          ++s.collisions_fused;
        } else {
          ++s.collisions_occluded;
          if (d1 > d_other) {
            new_map.Set(j, d1, v1, old_map.validity(i));
            new_map.SetEvidence(j, old_map.inlier_evidence(i), old_map.outlier_evidence(i));
            if (old_map.num_observations(i) > 0) new_map.CountObservation(j);
          }
        }
        continue;
      }
      new_map.Set(j, d1, v1, old_map.validity(i));
      new_map.SetEvidence(j, old_map.inlier_evidence(i), old_map.outlier_evidence(i));
      if (old_map.num_observations(i) > 0) new_map.CountObservation(j);  // stereo-based
      ++s.propagated;
    }
  }
  s.propagated = new_map.CountValid();
  return new_map;
}

}  // namespace pldvo
