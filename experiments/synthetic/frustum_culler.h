// Frustum culling of the synthetic scene's boxes: which primitives a bundle of camera rays
// through an image rectangle can hit. Used by the renderer (per tile and per supersampled pixel)
// and by the trajectory's path check (the whole image).
#ifndef PLDVO_EXPERIMENTS_SYNTHETIC_FRUSTUM_CULLER_H_
#define PLDVO_EXPERIMENTS_SYNTHETIC_FRUSTUM_CULLER_H_

#include <Eigen/Core>
#include <vector>

#include "core/pinhole_camera.h"
#include "experiments/synthetic/synthetic_sequence.h"

namespace pldvo::synthetic {

class FrustumCuller {
 public:
  // Keeps references: `scene` and `camera` must outlive the culler.
  FrustumCuller(const Scene& scene, const PinholeCamera& camera);

  // The primitives of `from` that may meet the frustum of the camera at (`rotation`, `origin`)
  // (world_from_cam) through the image rectangle [u0, u1] x [v0, v1]: a box is dropped when it
  // lies entirely outside one of the frustum's four side planes (box-plane separation with the
  // box's projected radius, exact for boxes). The room encloses the camera and is always kept.
  void Candidates(double u0, double v0, double u1, double v1, const Eigen::Matrix3d& rotation,
                  const Eigen::Vector3d& origin, const std::vector<int>& from,
                  std::vector<int>* candidates) const;

  // Every primitive index, the `from` of a first, whole-image call.
  const std::vector<int>& all() const { return all_primitives_; }

 private:
  const Scene& scene_;
  const PinholeCamera& camera_;
  std::vector<int> all_primitives_;
  std::vector<Eigen::Matrix3d> half_axes_;  // columns: the box axes in the world x half sizes
};

}  // namespace pldvo::synthetic

#endif  // PLDVO_EXPERIMENTS_SYNTHETIC_FRUSTUM_CULLER_H_
