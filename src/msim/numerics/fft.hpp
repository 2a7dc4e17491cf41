#pragma once
// N-dimensional complex FFT in single precision on kissfft (BSD-3-Clause; FFTW's GPL stays out of
// the project). Arrays are row-major with axis 0 fastest (x, then y, z, t), like core/Grid. Each
// axis is transformed line by line, the lines spread over the cores (kissfft's own N-d transform
// runs on one). Any size works (kissfft is mixed-radix); powers of 2, 3 and 5 are fastest.
#include <array>
#include <complex>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace msim::numerics {

class FftNd {
 public:
  // dims[a] samples along axis a (axis 0 fastest); every size >= 1. std::invalid_argument otherwise.
  explicit FftNd(std::vector<int> dims);
  ~FftNd();
  FftNd(FftNd&&) noexcept;
  FftNd& operator=(FftNd&&) noexcept;

  // In place, unnormalised: forward X_k = sum_n x_n exp(-2 pi i k.n / N) (per axis),
  // inverse x_n = sum_k X_k exp(+2 pi i k.n / N) (no 1 / N: inverse(forward(x)) = size() x).
  // std::invalid_argument if data.size() != size().
  void forward(std::span<std::complex<float>> data) const;
  void inverse(std::span<std::complex<float>> data) const;

  std::size_t size() const { return size_; }
  const std::vector<int>& dims() const { return dims_; }

 private:
  struct Plans;
  void transform(std::span<std::complex<float>> data, bool inverse) const;
  std::vector<int> dims_;
  std::size_t size_ = 0;
  std::unique_ptr<Plans> plans_;
};

// The signed frequency of FFT index `index` on an axis of n samples: index for index <= n / 2,
// index - n above (so the Nyquist index n / 2 of an even n counts as +n / 2).
inline int signedFrequency(int index, int n) { return 2 * index <= n ? index : index - n; }

// True for the Nyquist index n / 2 of an even n > 1: its wave is its own mirror image, so a
// derivative there is undefined and spectral synthesis leaves it empty.
inline bool isNyquist(int index, int n) { return n > 1 && n % 2 == 0 && 2 * index == n; }

// The modes of an N-d lattice (dims, axis 0 fastest) in mirror pairs, for synthesising real fields
// by an inverse FFT: f(index, mirror, frequency) is called once per pair, for the lower index of
// the pair (index < mirror), with `frequency` the signed frequencies of `index` (an int array
// indexable by axis, dims.size() of them). Modes that are their own mirror (zero and Nyquist
// frequencies on every axis) are skipped: a real field needs them real, and synthesis leaves them
// empty. Set u^(index) = c and u^(mirror) = conj(c) and the inverse transform is real. Pairs are
// visited in parallel; f must only write its own pair.
template <typename F>
void forEachMirrorPair(const std::vector<int>& dims, F&& f) {
  constexpr int kMaxDims = 8;
  std::size_t n = 1;
  for (const int d : dims) n *= static_cast<std::size_t>(d);
  const int rank = static_cast<int>(dims.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    std::array<int, kMaxDims> frequency{};
    for (std::size_t a = r.begin(); a != r.end(); ++a) {
      std::size_t rest = a, mirror = 0, stride = 1;
      bool selfMirror = true;
      for (int d = 0; d < rank; ++d) {
        const int m = dims[d];
        const int i = static_cast<int>(rest % m);
        rest /= m;
        frequency[d] = signedFrequency(i, m);
        const int j = (m - i) % m;
        selfMirror &= i == j;
        mirror += static_cast<std::size_t>(j) * stride;
        stride *= static_cast<std::size_t>(m);
      }
      if (selfMirror || mirror < a) continue;
      f(a, mirror, frequency);
    }
  });
}

}  // namespace msim::numerics
