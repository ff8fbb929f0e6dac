// Test helper: a seeded random texture, uniform white noise in [0, 255] blurred by a Gaussian.
#ifndef PLDVO_TESTS_RANDOM_TEXTURE_H_
#define PLDVO_TESTS_RANDOM_TEXTURE_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace pldvo::test {

// CV_8U, drawn from `rng` (which callers may go on drawing from); `kernel` (0, 0) lets OpenCV
// size the kernel from blur_sigma.
inline cv::Mat RandomTexture(cv::Size size, cv::RNG& rng, double blur_sigma,
                             cv::Size kernel = cv::Size(0, 0)) {
  cv::Mat texture(size, CV_8U);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, kernel, blur_sigma);
  return texture;
}

inline cv::Mat RandomTexture(cv::Size size, uint64_t seed, double blur_sigma,
                             cv::Size kernel = cv::Size(0, 0)) {
  cv::RNG rng(seed);
  return RandomTexture(size, rng, blur_sigma, kernel);
}

}  // namespace pldvo::test

#endif  // PLDVO_TESTS_RANDOM_TEXTURE_H_
