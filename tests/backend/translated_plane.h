// Test helper: a fronto-parallel textured plane seen by a camera translating along x, exactly (a
// shift of the texture by fx * baseline / depth px), for stereo tests with known geometry.
#ifndef PLDVO_TESTS_BACKEND_TRANSLATED_PLANE_H_
#define PLDVO_TESTS_BACKEND_TRANSLATED_PLANE_H_

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/imgproc.hpp>

#include "core/pinhole_camera.h"
#include "core/se3.h"

namespace pldvo::test {

// The scene of the translated-plane tests: a 160x120 camera, the plane at 1 m, its texture wider
// than the image by 40 px on each side.
inline const PinholeCamera kPlaneCamera{160, 120, 130.0, 130.0, 79.5, 59.5};
constexpr double kPlaneDepth = 1.0;
constexpr int kPlaneMargin = 40;

// A texture for that plane: uniform noise in [0, 255] blurred with sigma 2 px (CV_32F).
inline cv::Mat BlurredNoiseTexture(uint64_t seed) {
  cv::Mat texture(kPlaneCamera.height + 2 * kPlaneMargin, kPlaneCamera.width + 2 * kPlaneMargin,
                  CV_32F);
  cv::RNG rng(seed);
  rng.fill(texture, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
  return texture;
}

// The image of a camera at +baseline m along x of a plane at `depth` m whose texture (CV_32F)
// is wider than the image by `margin` px on each side.
inline cv::Mat TranslatedPlaneImage(const cv::Mat& texture, const PinholeCamera& camera,
                                    double depth, int margin, double baseline) {
  const double shift = camera.fx * baseline / depth;
  const cv::Mat warp = (cv::Mat_<double>(2, 3) << 1, 0, margin + shift, 0, 1, margin);
  cv::Mat image;
  cv::warpAffine(texture, image, warp, cv::Size(camera.width, camera.height),
                 cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
  return image;
}

// cur_from_ref of that camera.
inline SE3 TranslatedCurFromRef(double baseline) {
  return SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-baseline, 0.0, 0.0));
}

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_BACKEND_TRANSLATED_PLANE_H_
