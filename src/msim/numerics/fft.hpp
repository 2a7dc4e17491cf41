#pragma once
// N-dimensional complex FFT in single precision on kissfft (BSD-3-Clause; FFTW's GPL stays out of
// the project). Arrays are row-major with axis 0 fastest (x, then y, z, t), like core/Grid. Each
// axis is transformed line by line, the lines spread over the cores (kissfft's own N-d transform
// runs on one). Any size works (kissfft is mixed-radix); powers of 2, 3 and 5 are fastest.
#include <complex>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

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

}  // namespace msim::numerics
