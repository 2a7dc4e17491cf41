// numerics/fft against a direct discrete Fourier transform, on mixed (non power of 2) sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/fft.hpp"

using msim::numerics::FftNd;

namespace {

std::vector<std::complex<float>> randomArray(std::size_t n, std::uint64_t seed) {
  msim::Rng rng(seed);
  std::vector<std::complex<float>> x(n);
  for (auto& v : x) v = std::complex<float>(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)));
  return x;
}

}  // namespace

TEST(Fft, MatchesTheDirectTransformOnMixedSizes) {
  const std::vector<int> dims{6, 5, 3};  // axis 0 fastest
  const auto x = randomArray(90, 1);
  auto fast = x;
  FftNd(dims).forward(fast);
  double worst = 0.0, largest = 0.0;
  for (int k2 = 0; k2 < 3; ++k2)
    for (int k1 = 0; k1 < 5; ++k1)
      for (int k0 = 0; k0 < 6; ++k0) {
        std::complex<double> sum = 0.0;
        for (int n2 = 0; n2 < 3; ++n2)
          for (int n1 = 0; n1 < 5; ++n1)
            for (int n0 = 0; n0 < 6; ++n0) {
              const double phase = -2.0 * std::numbers::pi * (k0 * n0 / 6.0 + k1 * n1 / 5.0 + k2 * n2 / 3.0);
              sum += std::complex<double>(x[n0 + 6 * (n1 + 5 * n2)]) * std::polar(1.0, phase);
            }
        worst = std::max(worst, std::abs(sum - std::complex<double>(fast[k0 + 6 * (k1 + 5 * k2)])));
        largest = std::max(largest, std::abs(sum));
      }
  EXPECT_LT(worst, 1e-5 * largest);
}

TEST(Fft, InverseOfForwardIsSizeTimesTheInput) {
  const std::vector<int> dims{16, 8, 4, 2};
  const auto x = randomArray(16 * 8 * 4 * 2, 2);
  auto y = x;
  const FftNd fft(dims);
  fft.forward(y);
  fft.inverse(y);
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, double(std::abs(y[i] / float(x.size()) - x[i])));
  EXPECT_LT(worst, 1e-6);
}

TEST(Fft, SignedFrequenciesAndBadInput) {
  EXPECT_EQ(msim::numerics::signedFrequency(3, 8), 3);
  EXPECT_EQ(msim::numerics::signedFrequency(4, 8), 4);
  EXPECT_EQ(msim::numerics::signedFrequency(5, 8), -3);
  EXPECT_EQ(msim::numerics::signedFrequency(2, 5), 2);
  EXPECT_EQ(msim::numerics::signedFrequency(3, 5), -2);
  EXPECT_TRUE(msim::numerics::isNyquist(4, 8));
  EXPECT_FALSE(msim::numerics::isNyquist(2, 5));
  EXPECT_THROW(FftNd({4, 0}), std::invalid_argument);
  std::vector<std::complex<float>> wrong(7);
  EXPECT_THROW(FftNd({4, 2}).forward(wrong), std::invalid_argument);
}
