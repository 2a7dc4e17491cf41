#include "msim/core/transfer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim {

namespace {

// Each kernel fills the weights of its taps first, first+1, ... along one axis (sample space)
// and returns `first`.
struct LinearKernel {
  static constexpr int kSupport = 2;
  static int taps(double s, double* w) {
    const double first = std::floor(s);
    const double t = s - first;
    w[0] = 1.0 - t;
    w[1] = t;
    return static_cast<int>(first);
  }
};

struct QuadraticBSplineKernel {
  static constexpr int kSupport = 3;
  static int taps(double s, double* w) {
    const double first = std::floor(s + 0.5) - 1.0;
    const double x = s - first;  // in [0.5, 1.5): distance from the first tap
    w[0] = 0.5 * (1.5 - x) * (1.5 - x);
    w[1] = 0.75 - (x - 1.0) * (x - 1.0);
    w[2] = 0.5 * (x - 0.5) * (x - 0.5);
    return static_cast<int>(first);
  }
};

// Far outside the grid every tap folds onto the border sample anyway; clamping the coordinate to
// a band just beyond the grid keeps std::floor's result in int range (and maps NaN to the band's
// lower end) without changing any folded weight.
double clampToTapBand(double s, int n) {
  const double lo = -2.0, hi = static_cast<double>(n) + 1.0;
  return s > lo ? (s < hi ? s : hi) : lo;
}

// The folded taps of one particle: memory offsets and weights per axis.
template <typename Kernel, int D>
struct Stencil {
  static constexpr int K = Kernel::kSupport;
  std::ptrdiff_t offset[D][K];
  double weight[D][K];

  Stencil(const Grid<float, D>& grid, const Vecf<D>& position) {
    const Vec<D> s = grid.toSampleSpace(position.template cast<double>());
    for (int a = 0; a < D; ++a) {
      const int n = grid.size()[a];
      const int first = Kernel::taps(clampToTapBand(s[a], n), weight[a]);
      for (int k = 0; k < K; ++k) offset[a][k] = std::clamp(first + k, 0, n - 1) * grid.stride(a);
    }
  }

  // f(memory offset, weight) for every one of the K^D taps.
  template <int Axis = D - 1, typename F>
  void forEachTap(F&& f, std::ptrdiff_t base = 0, double w = 1.0) const {
    for (int k = 0; k < K; ++k) {
      if constexpr (Axis == 0)
        f(base + offset[0][k], w * weight[0][k]);
      else
        forEachTap<Axis - 1>(f, base + offset[Axis][k], w * weight[Axis][k]);
    }
  }
};

// The clamped first tap along the slowest axis decides which slab a particle belongs to.
template <typename Kernel, int D>
std::uint32_t slabOf(const Grid<float, D>& grid, const Vecf<D>& position, int slabWidth) {
  constexpr int A = D - 1;
  const int n = grid.size()[A];
  const double s = (static_cast<double>(position[A]) - grid.spec().origin[A]) / grid.spec().dx - grid.offset()[A];
  double w[Kernel::kSupport];
  const int first = std::clamp(Kernel::taps(clampToTapBand(s, n), w), 0, n - 1);
  return static_cast<std::uint32_t>(first / slabWidth);
}

template <typename F>
decltype(auto) withKernel(TransferKernel kernel, F&& f) {
  if (kernel == TransferKernel::Linear) return f(LinearKernel{});
  return f(QuadraticBSplineKernel{});
}

}  // namespace

template <int D>
template <typename Kernel>
void Splatter<D>::bucketBySlab(std::span<const Vecf<D>> positions, const Grid<float, D>& target) {
  const std::size_t slabs = (target.size()[D - 1] + kSlabWidth - 1) / kSlabWidth;
  buckets_.sort(positions.size(), slabs, [&](std::size_t i) { return slabOf<Kernel>(target, positions[i], kSlabWidth); });
}

template <int D>
template <typename Kernel, std::size_t N, typename ValueOf>
void Splatter<D>::splatWith(std::span<const Vecf<D>> positions, const ValueOf& valueOf,
                            const std::array<Grid<float, D>*, N>& targets, SplatMode mode, float emptyValue) {
  static_assert(Kernel::kSupport - 1 <= kSlabWidth, "slabs of one colour must not share samples");
  const Grid<float, D>& layout = *targets[0];
  for (const Grid<float, D>* t : targets)
    if (t->size() != layout.size() || t->offset() != layout.offset() || t->spec().dx != layout.spec().dx ||
        t->spec().origin != layout.spec().origin)
      throw std::invalid_argument("splat: the grids of one splat must share their layout");
  const bool normalized = mode == SplatMode::Normalized;
  const std::size_t samples = layout.count();
  // The N sums of a sample lie side by side, so a tap touches one cache line for all of them.
  weightedSum_.resize(samples * N);
  weightSum_.resize(normalized ? samples : 0);
  parallelFor(0, samples, [&](std::size_t i) {
    for (std::size_t q = 0; q < N; ++q) weightedSum_[i * N + q] = 0.0;
    if (normalized) weightSum_[i] = 0.0;
  }, 1 << 14);

  bucketBySlab<Kernel>(positions, layout);

  const std::size_t slabs = buckets_.buckets();
  const std::span<const std::uint32_t> order = buckets_.order();
  double* sum = weightedSum_.data();
  double* weight = weightSum_.data();
  for (std::size_t colour = 0; colour < 2; ++colour) {
    const std::size_t slabsOfColour = (slabs + 1 - colour) / 2;
    tbb::parallel_for(std::size_t(0), slabsOfColour, [&](std::size_t j) {
      const std::size_t slab = 2 * j + colour;
      for (std::size_t k = buckets_.begin(slab); k < buckets_.begin(slab + 1); ++k) {
        const std::uint32_t p = order[k];
        double v[N];
        for (std::size_t q = 0; q < N; ++q) v[q] = valueOf(p, q);
        const Stencil<Kernel, D> stencil(layout, positions[p]);
        stencil.forEachTap([&](std::ptrdiff_t at, double w) {
          for (std::size_t q = 0; q < N; ++q) sum[at * N + q] += w * v[q];
          if (normalized) weight[at] += w;
        });
      }
    });
  }

  for (std::size_t q = 0; q < N; ++q) {
    float* out = targets[q]->data().data();
    if (normalized)
      parallelFor(0, samples, [&](std::size_t i) {
        out[i] = weight[i] > 0.0 ? static_cast<float>(sum[i * N + q] / weight[i]) : emptyValue;
      }, 1 << 14);
    else
      parallelFor(0, samples, [&](std::size_t i) { out[i] = static_cast<float>(out[i] + sum[i * N + q]); }, 1 << 14);
  }
}

template <int D>
template <std::size_t N>
void Splatter<D>::splatSums(std::span<const Vecf<D>> positions, const std::array<std::span<const float>, N>& values,
                            const std::array<Grid<float, D>*, N>& targets, TransferKernel kernel) {
  for (const std::span<const float>& v : values)
    if (v.size() != positions.size())
      throw std::invalid_argument("splat: " + std::to_string(v.size()) + " values for " +
                                  std::to_string(positions.size()) + " positions");
  withKernel(kernel, [&](auto k) {
    splatWith<decltype(k), N>(
        positions, [&](std::size_t p, std::size_t q) { return values[q][p]; }, targets, SplatMode::Sum, 0.0f);
  });
}

template <int D>
void Splatter<D>::splat(std::span<const Vecf<D>> positions, std::span<const float> values, Grid<float, D>& target,
                        TransferKernel kernel, SplatMode mode, float emptyValue) {
  if (values.size() != positions.size())
    throw std::invalid_argument("splat: " + std::to_string(values.size()) + " values for " +
                                std::to_string(positions.size()) + " positions");
  withKernel(kernel, [&](auto k) {
    splatWith<decltype(k), 1>(
        positions, [&](std::size_t p, std::size_t) { return values[p]; }, {&target}, mode, emptyValue);
  });
}

template <int D>
void Splatter<D>::splat(std::span<const Vecf<D>> positions, std::span<const Vecf<D>> values, MacGrid<D>& target,
                        TransferKernel kernel, SplatMode mode, float emptyValue) {
  if (values.size() != positions.size())
    throw std::invalid_argument("splat: " + std::to_string(values.size()) + " values for " +
                                std::to_string(positions.size()) + " positions");
  withKernel(kernel, [&](auto k) {
    for (int a = 0; a < D; ++a)
      splatWith<decltype(k), 1>(
          positions, [&](std::size_t p, std::size_t) { return values[p][a]; }, {&target.component(a)}, mode,
          emptyValue);
  });
}

template <int D>
void splat(std::type_identity_t<std::span<const Vecf<D>>> positions, std::span<const float> values,
           Grid<float, D>& target, TransferKernel kernel, SplatMode mode, float emptyValue) {
  Splatter<D>().splat(positions, values, target, kernel, mode, emptyValue);
}

template <int D>
void splat(std::type_identity_t<std::span<const Vecf<D>>> positions,
           std::type_identity_t<std::span<const Vecf<D>>> values, MacGrid<D>& target, TransferKernel kernel,
           SplatMode mode, float emptyValue) {
  Splatter<D>().splat(positions, values, target, kernel, mode, emptyValue);
}

template <int D>
void gather(const Grid<float, D>& grid, std::type_identity_t<std::span<const Vecf<D>>> positions,
            TransferKernel kernel, std::span<float> out) {
  if (out.size() != positions.size())
    throw std::invalid_argument("gather: output holds " + std::to_string(out.size()) + " values for " +
                                std::to_string(positions.size()) + " positions");
  const float* data = grid.data().data();
  withKernel(kernel, [&](auto k) {
    parallelFor(0, positions.size(), [&](std::size_t p) {
      double value = 0.0;
      Stencil<decltype(k), D>(grid, positions[p]).forEachTap([&](std::ptrdiff_t at, double w) {
        value += w * data[at];
      });
      out[p] = static_cast<float>(value);
    });
  });
}

template <int D>
std::vector<float> gather(const Grid<float, D>& grid, std::type_identity_t<std::span<const Vecf<D>>> positions,
                          TransferKernel kernel) {
  std::vector<float> out(positions.size());
  gather<D>(grid, positions, kernel, out);
  return out;
}

template <int D, std::size_t N>
void gather(const std::array<const MacGrid<D>*, N>& grids, std::type_identity_t<std::span<const Vecf<D>>> positions,
            TransferKernel kernel, const std::array<std::span<Vecf<D>>, N>& out) {
  for (std::size_t q = 0; q < N; ++q) {
    if (out[q].size() != positions.size())
      throw std::invalid_argument("gather: output holds " + std::to_string(out[q].size()) + " values for " +
                                  std::to_string(positions.size()) + " positions");
    if (grids[q]->spec().res != grids[0]->spec().res || grids[q]->spec().dx != grids[0]->spec().dx ||
        grids[q]->spec().origin != grids[0]->spec().origin)
      throw std::invalid_argument("gather: the MAC grids of one gather must share their layout");
  }
  withKernel(kernel, [&](auto k) {
    for (int a = 0; a < D; ++a) {
      const Grid<float, D>& layout = grids[0]->component(a);
      parallelFor(0, positions.size(), [&](std::size_t p) {
        const Stencil<decltype(k), D> stencil(layout, positions[p]);
        for (std::size_t q = 0; q < N; ++q) {
          const float* data = grids[q]->component(a).data().data();
          double value = 0.0;
          stencil.forEachTap([&](std::ptrdiff_t at, double w) { value += w * data[at]; });
          out[q][p][a] = static_cast<float>(value);
        }
      });
    }
  });
}

template <int D>
void gather(const MacGrid<D>& grid, std::type_identity_t<std::span<const Vecf<D>>> positions, TransferKernel kernel,
            std::type_identity_t<std::span<Vecf<D>>> out) {
  gather<D, 1>({&grid}, positions, kernel, {out});
}

#define MSIM_INSTANTIATE_TRANSFER(D)                                                                                \
  template class Splatter<D>;                                                                                       \
  template void Splatter<D>::splatSums<2>(std::span<const Vecf<D>>, const std::array<std::span<const float>, 2>&,   \
                                          const std::array<Grid<float, D>*, 2>&, TransferKernel);                   \
  template void Splatter<D>::splatSums<3>(std::span<const Vecf<D>>, const std::array<std::span<const float>, 3>&,   \
                                          const std::array<Grid<float, D>*, 3>&, TransferKernel);                   \
  template void splat<D>(std::span<const Vecf<D>>, std::span<const float>, Grid<float, D>&, TransferKernel,        \
                         SplatMode, float);                                                                         \
  template void splat<D>(std::span<const Vecf<D>>, std::span<const Vecf<D>>, MacGrid<D>&, TransferKernel,          \
                         SplatMode, float);                                                                         \
  template void gather<D>(const Grid<float, D>&, std::span<const Vecf<D>>, TransferKernel, std::span<float>);      \
  template std::vector<float> gather<D>(const Grid<float, D>&, std::span<const Vecf<D>>, TransferKernel);          \
  template void gather<D>(const MacGrid<D>&, std::span<const Vecf<D>>, TransferKernel, std::span<Vecf<D>>);       \
  template void gather<D, 2>(const std::array<const MacGrid<D>*, 2>&, std::span<const Vecf<D>>, TransferKernel,    \
                             const std::array<std::span<Vecf<D>>, 2>&);

MSIM_INSTANTIATE_TRANSFER(2)
MSIM_INSTANTIATE_TRANSFER(3)
#undef MSIM_INSTANTIATE_TRANSFER

}  // namespace msim
