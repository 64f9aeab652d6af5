// Deterministic hashing, per-purpose random generators and world-anchored
// value noise for the simulator.
//
// Randomness never comes from a shared generator: each purpose (road, world,
// database, one image's noise...) gets its own std::mt19937_64 seeded by
// SubSeed(seed, purpose, index), and textures are pure functions of world
// coordinates (value noise on an integer lattice hashed with a salt), so the
// same ground looks the same from every exposure and every thread.
#ifndef ZEBRAGEO_SIMULATOR_NOISE_H_
#define ZEBRAGEO_SIMULATOR_NOISE_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace zebrageo::sim {

// splitmix64 finaliser: a bijective 64-bit mix.
inline uint64_t Mix64(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  x ^= x >> 31;
  return x;
}

// Seed of the generator for `purpose` (a small constant per use) and `index`
// (an image, a crossing...).
inline uint64_t SubSeed(uint64_t seed, uint64_t purpose, uint64_t index = 0) {
  return Mix64(Mix64(seed ^ 0x5a17e5eedULL) + Mix64(purpose * 0x9e37 + 1) +
               index * 0x9e3779b97f4a7c15ULL);
}

// Uniform in [0, 1) from a hash (24 bits).
inline float HashToUnit(uint64_t h) {
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
}

inline uint64_t HashLattice(int64_t ix, int64_t iy, uint64_t salt) {
  return Mix64(static_cast<uint64_t>(ix) * 0x9e3779b97f4a7c15ULL ^
               (static_cast<uint64_t>(iy) * 0xc2b2ae3d27d4eb4fULL + salt));
}

// 32-bit hash of a lattice point (lowbias32 finaliser): cheaper than
// HashLattice for textures evaluated millions of times per image.
inline uint32_t HashLattice32(int64_t ix, int64_t iy, uint32_t salt) {
  uint32_t h = static_cast<uint32_t>(ix) * 0x8da6b343u ^
               static_cast<uint32_t>(iy) * 0xd8163841u ^ salt;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// Value noise in [0, 1]: smooth (C1) bilinear interpolation of hashed
// lattice values at integer (x, y). Scale the arguments for the feature size.
inline float ValueNoise(double x, double y, uint64_t salt) {
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const auto ix = static_cast<int64_t>(fx);
  const auto iy = static_cast<int64_t>(fy);
  float u = static_cast<float>(x - fx);
  float v = static_cast<float>(y - fy);
  u = u * u * (3.0f - 2.0f * u);
  v = v * v * (3.0f - 2.0f * v);
  const auto salt32 = static_cast<uint32_t>(salt ^ (salt >> 32));
  constexpr float kScale = 1.0f / 4294967296.0f;
  const float a = HashLattice32(ix, iy, salt32) * kScale;
  const float b = HashLattice32(ix + 1, iy, salt32) * kScale;
  const float c = HashLattice32(ix, iy + 1, salt32) * kScale;
  const float d = HashLattice32(ix + 1, iy + 1, salt32) * kScale;
  const float ab = a + (b - a) * u;
  const float cd = c + (d - c) * u;
  return ab + (cd - ab) * v;
}

// Standard normal from two independent hashes (Box-Muller).
inline float HashGaussian(uint64_t h) {
  const uint64_t h2 = Mix64(h + 0x632be59bd9b4e019ULL);
  const float u1 = (static_cast<float>(h >> 40) + 0.5f) * (1.0f / 16777216.0f);
  const float u2 = HashToUnit(h2);
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(6.28318530718f * u2);
}

inline double SmoothStep(double edge0, double edge1, double x) {
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// Uniform real in [a, b) from a generator (libstdc++'s distributions are
// deterministic on a platform; this keeps the draw order explicit).
inline double Uniform(std::mt19937_64* rng, double a, double b) {
  return a + (b - a) * (static_cast<double>((*rng)() >> 11) * 0x1.0p-53);
}

inline double Gaussian(std::mt19937_64* rng, double sigma) {
  const double u1 = (static_cast<double>((*rng)() >> 11) + 0.5) * 0x1.0p-53;
  const double u2 = static_cast<double>((*rng)() >> 11) * 0x1.0p-53;
  return sigma * std::sqrt(-2.0 * std::log(u1)) *
         std::cos(6.283185307179586 * u2);
}

// Integer in [a, b] (inclusive).
inline int UniformInt(std::mt19937_64* rng, int a, int b) {
  if (b <= a) return a;
  return a + static_cast<int>((*rng)() % static_cast<uint64_t>(b - a + 1));
}

inline bool Bernoulli(std::mt19937_64* rng, double p) {
  return Uniform(rng, 0.0, 1.0) < p;
}

// Poisson-distributed count with mean `mean` (Knuth; small means only).
inline int PoissonCount(std::mt19937_64* rng, double mean) {
  if (mean <= 0.0) return 0;
  if (mean > 50.0) {
    return std::max(0, static_cast<int>(
                           std::lround(mean + Gaussian(rng, std::sqrt(mean)))));
  }
  const double limit = std::exp(-mean);
  double product = Uniform(rng, 0.0, 1.0);
  int count = 0;
  while (product > limit) {
    ++count;
    product *= Uniform(rng, 0.0, 1.0);
  }
  return count;
}

}  // namespace zebrageo::sim

#endif  // ZEBRAGEO_SIMULATOR_NOISE_H_
