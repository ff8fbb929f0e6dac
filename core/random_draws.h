// Vectors of independent random draws in a fixed order.
//
// C++ leaves the evaluation order of function arguments unspecified: gcc evaluates
// Eigen::Vector3d(d(rng), d(rng), d(rng)) right to left, clang left to right, so the same seed
// gave different simulated data with the two compilers. These helpers draw the last coordinate
// first, the order gcc used, in which the project's seeded figures were measured.
#ifndef PLDVO_CORE_RANDOM_DRAWS_H_
#define PLDVO_CORE_RANDOM_DRAWS_H_

#include <Eigen/Core>

namespace pldvo {

template <class Distribution, class Rng>
Eigen::Vector2d DrawVector2(Distribution& distribution, Rng& rng) {
  const double y = distribution(rng);
  const double x = distribution(rng);
  return Eigen::Vector2d(x, y);
}

template <class Distribution, class Rng>
Eigen::Vector3d DrawVector3(Distribution& distribution, Rng& rng) {
  const double z = distribution(rng);
  const double y = distribution(rng);
  const double x = distribution(rng);
  return Eigen::Vector3d(x, y, z);
}

}  // namespace pldvo

#endif  // PLDVO_CORE_RANDOM_DRAWS_H_
