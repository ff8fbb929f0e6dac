#include "experiments/synthetic/frustum_culler.h"

namespace pldvo::synthetic {

FrustumCuller::FrustumCuller(const Scene& scene, const PinholeCamera& camera)
    : scene_(scene), camera_(camera) {
  const auto& primitives = scene.primitives();
  all_primitives_.resize(primitives.size());
  half_axes_.resize(primitives.size());
  for (size_t p = 0; p < primitives.size(); ++p) {
    all_primitives_[p] = static_cast<int>(p);
    for (int a = 0; a < 3; ++a) {
      half_axes_[p].col(a) =
          primitives[p].box_from_world_rotation.row(a).transpose() * primitives[p].half_size[a];
    }
  }
}

void FrustumCuller::Candidates(double u0, double v0, double u1, double v1,
                               const Eigen::Matrix3d& rotation, const Eigen::Vector3d& origin,
                               const std::vector<int>& from, std::vector<int>* candidates) const {
  const Eigen::Vector3d corner[4] = {rotation * camera_.Unproject(Eigen::Vector2d(u0, v0)),
                                     rotation * camera_.Unproject(Eigen::Vector2d(u1, v0)),
                                     rotation * camera_.Unproject(Eigen::Vector2d(u1, v1)),
                                     rotation * camera_.Unproject(Eigen::Vector2d(u0, v1))};
  const Eigen::Vector3d inside = corner[0] + corner[1] + corner[2] + corner[3];
  Eigen::Vector3d normal[4];
  for (int k = 0; k < 4; ++k) {
    normal[k] = corner[k].cross(corner[(k + 1) % 4]);
    if (normal[k].dot(inside) < 0.0) normal[k] = -normal[k];
  }
  candidates->clear();
  const auto& primitives = scene_.primitives();
  for (const int p : from) {
    if (primitives[p].kind == Primitive::Kind::kRoom) {
      candidates->push_back(p);
      continue;
    }
    const Eigen::Vector3d offset = primitives[p].center_in_world - origin;
    bool outside = false;
    for (int k = 0; k < 4 && !outside; ++k) {
      const double radius = (normal[k].transpose() * half_axes_[p]).cwiseAbs().sum();
      outside = normal[k].dot(offset) < -radius * (1.0 + 1e-9) - 1e-12;
    }
    if (!outside) candidates->push_back(p);
  }
}

}  // namespace pldvo::synthetic
