#pragma once
// Cheap deterministic per-pixel randomness: SplitMix64 plus a table of standard normals. std::mt19937_64 seeds
// everything (scene layout, per-frame streams); this is only for the millions of per-pixel draws.
#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace varslam::synth {

struct SplitMix64 {
  std::uint64_t state;
  explicit SplitMix64(std::uint64_t seed) : state(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
};

/// 2^16 standard-normal samples drawn once; lookups with random indices give fast Gaussian noise.
class GaussianTable {
 public:
  explicit GaussianTable(std::uint64_t seed) : values_(kSize) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (auto& v : values_) v = n(rng);
  }
  float draw(SplitMix64& r) const { return values_[r.next() & (kSize - 1)]; }

 private:
  static constexpr std::size_t kSize = 1u << 16;
  std::vector<float> values_;
};

/// Mix two values into a well-distributed seed (frame streams from the scene seed).
inline std::uint64_t mix_seed(std::uint64_t a, std::uint64_t b) {
  SplitMix64 s(a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull));
  s.next();
  return s.next();
}

}  // namespace varslam::synth
