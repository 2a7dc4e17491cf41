#pragma once
// Rng: seeded, reproducible random numbers (xoshiro256** seeded through splitmix64, the pairing its
// authors recommend). The same seed gives the same sequence on every platform, unlike the
// distributions of <random>, whose algorithms are implementation-defined.
//
// Parallel use: split(streamId) derives an independent generator from this one's seed and the
// id only (not from how many numbers were drawn), so giving every task/block/agent its own
// rng.split(id) makes a parallel run reproducible whatever the thread count or scheduling.
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace msim {

class Rng {
 public:
  using result_type = std::uint64_t;  // usable as a UniformRandomBitGenerator (std::shuffle, ...)

  explicit Rng(std::uint64_t seed = 0) : seed_(seed) {
    std::uint64_t x = seed;
    for (auto& s : state_) s = splitmix64(x);
  }

  std::uint64_t seed() const { return seed_; }

  // A generator whose stream is unrelated to this one's and to every other streamId's.
  Rng split(std::uint64_t streamId) const {
    std::uint64_t x = seed_ ^ 0x6a09e667f3bcc909ull;
    const std::uint64_t a = splitmix64(x);
    x = streamId + a;
    return Rng(splitmix64(x) ^ a);
  }

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<result_type>::max(); }
  result_type operator()() { return next(); }

  std::uint64_t next() {
    const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
    const std::uint64_t t = state_[1] << 17;
    state_[2] ^= state_[0];
    state_[3] ^= state_[1];
    state_[1] ^= state_[2];
    state_[0] ^= state_[3];
    state_[2] ^= t;
    state_[3] = rotl(state_[3], 45);
    return result;
  }

  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  // Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  // Uniform integer in [lo, hi] (inclusive), unbiased (Lemire's multiply-and-reject).
  std::int64_t uniformInt(std::int64_t lo, std::int64_t hi) {
    const std::uint64_t range = static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo) + 1;
    if (range == 0) return static_cast<std::int64_t>(next());  // the full 64-bit range
    unsigned __int128 m = static_cast<unsigned __int128>(next()) * range;
    if (static_cast<std::uint64_t>(m) < range) {
      const std::uint64_t threshold = (0 - range) % range;
      while (static_cast<std::uint64_t>(m) < threshold) m = static_cast<unsigned __int128>(next()) * range;
    }
    return lo + static_cast<std::int64_t>(m >> 64);
  }
  // Standard normal (Box-Muller; the second value of each pair is kept for the next call).
  double normal() {
    if (hasSpare_) {
      hasSpare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]: log stays finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
    hasSpare_ = true;
    return r * std::cos(2.0 * std::numbers::pi * u2);
  }
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix64(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

  std::uint64_t seed_;
  std::uint64_t state_[4];
  double spare_ = 0.0;
  bool hasSpare_ = false;
};

}  // namespace msim
