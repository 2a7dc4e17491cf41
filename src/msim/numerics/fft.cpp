#include "msim/numerics/fft.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <kiss_fft.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace msim::numerics {

namespace {
struct PlanDeleter {
  void operator()(kiss_fft_state* p) const { kiss_fft_free(p); }
};
using Plan = std::unique_ptr<kiss_fft_state, PlanDeleter>;
}  // namespace

// One forward and one inverse kissfft plan per axis. A plan is read-only while transforming, so
// the threads share it.
struct FftNd::Plans {
  std::vector<Plan> forward, inverse;
};

FftNd::FftNd(std::vector<int> dims) : dims_(std::move(dims)), plans_(std::make_unique<Plans>()) {
  if (dims_.empty()) throw std::invalid_argument("FftNd: no dimensions");
  size_ = 1;
  for (const int n : dims_) {
    if (n < 1) throw std::invalid_argument("FftNd: every dimension needs at least 1 sample, got " + std::to_string(n));
    size_ *= static_cast<std::size_t>(n);
    plans_->forward.emplace_back(kiss_fft_alloc(n, 0, nullptr, nullptr));
    plans_->inverse.emplace_back(kiss_fft_alloc(n, 1, nullptr, nullptr));
    if (!plans_->forward.back() || !plans_->inverse.back()) throw std::bad_alloc();
  }
}

FftNd::~FftNd() = default;
FftNd::FftNd(FftNd&&) noexcept = default;
FftNd& FftNd::operator=(FftNd&&) noexcept = default;

void FftNd::forward(std::span<std::complex<float>> data) const { transform(data, false); }
void FftNd::inverse(std::span<std::complex<float>> data) const { transform(data, true); }

void FftNd::transform(std::span<std::complex<float>> data, bool inverse) const {
  if (data.size() != size_)
    throw std::invalid_argument("FftNd: " + std::to_string(data.size()) + " samples given, the plan is for " +
                                std::to_string(size_));
  // std::complex<float> is laid out as float[2] ([complex.numbers]), like kiss_fft_cpx.
  auto* cpx = reinterpret_cast<kiss_fft_cpx*>(data.data());
  std::size_t stride = 1;
  for (std::size_t a = 0; a < dims_.size(); ++a) {
    const int n = dims_[a];
    if (n > 1) {
      kiss_fft_state* plan = (inverse ? plans_->inverse : plans_->forward)[a].get();
      // Lines along axis a: an outer index o (the axes after a) and an inner one i (those before).
      const std::size_t inner = stride, lines = size_ / static_cast<std::size_t>(n);
      const std::size_t grain = std::max<std::size_t>(1, 4096 / static_cast<std::size_t>(n));
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lines, grain), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<kiss_fft_cpx> line(static_cast<std::size_t>(n));  // once per task, not per line
        for (std::size_t q = r.begin(); q != r.end(); ++q) {
          const std::size_t o = q / inner, i = q % inner;
          kiss_fft_cpx* first = cpx + o * inner * static_cast<std::size_t>(n) + i;
          kiss_fft_stride(plan, first, line.data(), static_cast<int>(inner));
          for (int k = 0; k < n; ++k) first[static_cast<std::size_t>(k) * inner] = line[static_cast<std::size_t>(k)];
        }
      });
    }
    stride *= static_cast<std::size_t>(n);
  }
}

}  // namespace msim::numerics
