// Tests of FrustumCuller (experiments/synthetic/frustum_culler.h): culling is exact, i.e. a ray
// through the image rectangle hits the same surface at the same depth whether it tests the culled
// boxes or every primitive, and it does drop boxes.
#include "experiments/synthetic/frustum_culler.h"

#include <gtest/gtest.h>

#include <vector>

#include "experiments/synthetic/synthetic_internal.h"
#include "experiments/synthetic/synthetic_sequence.h"
#include "tests/small_lowtex_options.h"

namespace pldvo::synthetic {
namespace {

TEST(FrustumCullerTest, RaysThroughTheRectangleHitWhatTheWholeSceneGives) {
  internal::Rng rng(7);
  int culled_frames = 0, frames = 0;
  for (const int seed : {1, 2, 3}) {
    SynthOptions options = test::SmallLowtexOptions(40);  // at half its size
    options.seed = seed;
    options.width /= 2;
    options.height /= 2;
    options.fx = options.fy = options.fx / 2.0;
    const SyntheticSequence sequence = MakeSequence(options);
    const PinholeCamera& camera = sequence.camera;
    const FrustumCuller culler(sequence.scene, camera);
    std::vector<int> candidates;
    for (const StampedPose& pose : sequence.ground_truth) {
      const Eigen::Matrix3d rotation = pose.world_from_cam.rotation_matrix();
      const Eigen::Vector3d origin = pose.world_from_cam.translation();
      // A random sub-rectangle of the image (the renderer's tiles and pixels) or the whole image.
      const bool whole = (frames % 2 == 0);
      const double u0 = whole ? -0.5 : rng.Uniform(-0.5, camera.width - 10.0);
      const double v0 = whole ? -0.5 : rng.Uniform(-0.5, camera.height - 10.0);
      const double u1 = whole ? camera.width - 0.5 : u0 + rng.Uniform(0.5, 10.0);
      const double v1 = whole ? camera.height - 0.5 : v0 + rng.Uniform(0.5, 10.0);
      culler.Candidates(u0, v0, u1, v1, rotation, origin, culler.all(), &candidates);
      ++frames;
      if (candidates.size() < culler.all().size()) ++culled_frames;
      // The rectangle's corners and random rays inside it.
      for (int i = 0; i < 40; ++i) {
        const Eigen::Vector2d pixel =
            i < 4 ? Eigen::Vector2d(i % 2 == 0 ? u0 : u1, i < 2 ? v0 : v1)
                  : Eigen::Vector2d(rng.Uniform(u0, u1), rng.Uniform(v0, v1));
        const Eigen::Vector3d direction = rotation * camera.Unproject(pixel);
        Scene::Hit all_hit, culled_hit;
        const bool hit_all = sequence.scene.Intersect(origin, direction, &all_hit);
        const bool hit_culled = sequence.scene.IntersectSubset(
            origin, direction, candidates.data(), static_cast<int>(candidates.size()), &culled_hit);
        ASSERT_EQ(hit_all, hit_culled) << "seed " << seed << " pixel " << pixel.transpose();
        if (!hit_all) continue;
        EXPECT_EQ(all_hit.t, culled_hit.t) << "seed " << seed << " pixel " << pixel.transpose();
        EXPECT_EQ(all_hit.primitive, culled_hit.primitive);
        EXPECT_EQ(all_hit.face, culled_hit.face);
      }
    }
  }
  // Culling does something: most views leave boxes out.
  EXPECT_GT(culled_frames, frames / 2) << culled_frames << " of " << frames;
}

}  // namespace
}  // namespace pldvo::synthetic
