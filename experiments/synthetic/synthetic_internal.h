// Helpers shared by the synthetic scene, trajectory and renderer: a portable seeded random
// generator (the same numbers on every platform, unlike std:: distributions), counter-based
// hashing for per-pixel noise, and value noise for the procedural textures.
#ifndef PLDVO_EXPERIMENTS_SYNTHETIC_SYNTHETIC_INTERNAL_H_
#define PLDVO_EXPERIMENTS_SYNTHETIC_SYNTHETIC_INTERNAL_H_

#include <cmath>
#include <cstdint>

namespace pldvo::synthetic::internal {

// SplitMix64 (Steele et al. 2014): a bijective 64-bit mix.
inline uint64_t Mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Uniform double in [0, 1) from 64 random bits.
inline double ToUnit(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(Mix64(seed ^ 0x5DEECE66Dull)) {}
  uint64_t Next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return Mix64(state_);
  }
  double Uniform() { return ToUnit(Next()); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Integer in [lo, hi].
  int UniformInt(int lo, int hi) {
    const int value = lo + static_cast<int>(Uniform() * (hi - lo + 1));
    return value > hi ? hi : value;
  }
  bool Bernoulli(double p) { return Uniform() < p; }

 private:
  uint64_t state_;
};

// Standard normal from a 64-bit key (Box-Muller on two derived uniforms).
inline double GaussianFromKey(uint64_t key) {
  const uint64_t a = Mix64(key);
  const uint64_t b = Mix64(a ^ 0xD1B54A32D192ED03ull);
  const double u1 = (static_cast<double>(a >> 11) + 0.5) * 0x1.0p-53;  // (0, 1)
  const double u2 = ToUnit(b);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// Value in [0, 1) of the integer lattice point (i, j) for a texture seed.
inline double LatticeValue(int64_t i, int64_t j, uint32_t seed) {
  const uint64_t key = (static_cast<uint64_t>(i) * 0x8DA6B343ull) ^
                       (static_cast<uint64_t>(j) * 0xD8163841ull) ^
                       (static_cast<uint64_t>(seed) << 32);
  return ToUnit(Mix64(key));
}

// Smoothly interpolated value noise in [0, 1] (C1, smoothstep weights).
inline double ValueNoise(double x, double y, uint32_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t i = static_cast<int64_t>(fx), j = static_cast<int64_t>(fy);
  double sx = x - fx, sy = y - fy;
  sx = sx * sx * (3.0 - 2.0 * sx);
  sy = sy * sy * (3.0 - 2.0 * sy);
  const double v00 = LatticeValue(i, j, seed), v10 = LatticeValue(i + 1, j, seed);
  const double v01 = LatticeValue(i, j + 1, seed), v11 = LatticeValue(i + 1, j + 1, seed);
  return (v00 + sx * (v10 - v00)) + sy * ((v01 + sx * (v11 - v01)) - (v00 + sx * (v10 - v00)));
}

}  // namespace pldvo::synthetic::internal

#endif  // PLDVO_EXPERIMENTS_SYNTHETIC_SYNTHETIC_INTERNAL_H_
