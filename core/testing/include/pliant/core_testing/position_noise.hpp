// Position noise for simulated recordings: what a camera adds to every observed coordinate.
//
// Three generators are kept because recorded presses, and the test thresholds tuned on them,
// depend on their exact numbers. All draw in recording order: frame by frame, particle by
// particle, axis by axis. Host-independent, no exceptions (test support, heap allowed).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace pliant::core_testing {

/// splitmix64: a fixed, platform-independent hash of a 64-bit key.
inline std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Zero-mean, unit-variance noise from a key: Irwin-Hall sum of 4 uniforms, rescaled. The same
/// on every platform and standard library.
inline double unit_noise(std::uint64_t key) {
  double sum = 0;
  for (std::uint64_t k = 0; k < 4; ++k) {
    const std::uint64_t bits = mix(key * 4 + k) >> 11;  // 53 bits
    sum += static_cast<double>(bits) / 9007199254740992.0 - 0.5;
  }
  return sum * std::sqrt(3.0);
}

enum class NoiseSource {
  /// std::normal_distribution<double> on std::mt19937(seed): the core tests' presses.
  normal_mt19937,
  /// std::normal_distribution<double> on std::mt19937_64(seed): the host scenarios.
  normal_mt19937_64,
  /// unit_noise of a key from (seed, frame, coordinate), independent of draw order and of the
  /// standard library: the benchmarks.
  hashed,
};

/// Gaussian-like noise added to each recorded coordinate. std == 0 draws nothing and adds
/// +0.0 to every coordinate.
struct PositionNoise {
  NoiseSource source = NoiseSource::normal_mt19937_64;
  double std = 0.0;  ///< standard deviation, the model's length unit; >= 0
  std::uint64_t seed = 1;
};

/// One recording's noise, drawn coordinate by coordinate in recording order.
class NoiseStream {
 public:
  explicit NoiseStream(const PositionNoise& noise)
      : noise_(noise), engine32_(static_cast<std::mt19937::result_type>(noise.seed)), engine64_(noise.seed) {}

  /// Noise of one coordinate of frame `frame`; `coordinate` = particle * Dim + axis. Call once
  /// per coordinate in recording order (the engines' sequences depend on it).
  double next(int frame, int coordinate) {
    if (!(noise_.std > 0.0)) return 0.0;
    switch (noise_.source) {
      case NoiseSource::normal_mt19937: return noise_.std * normal_(engine32_);
      case NoiseSource::normal_mt19937_64: return noise_.std * normal_(engine64_);
      case NoiseSource::hashed: break;
    }
    constexpr std::uint64_t kPrime = 1000003;
    const std::uint64_t key =
        (noise_.seed * kPrime + static_cast<std::uint64_t>(frame)) * kPrime + static_cast<std::uint64_t>(coordinate);
    return noise_.std * unit_noise(key);
  }

 private:
  PositionNoise noise_;
  std::mt19937 engine32_;
  std::mt19937_64 engine64_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace pliant::core_testing
