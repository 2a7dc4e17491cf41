#pragma once
// Grid<T,D>: a dense array of samples over a GridSpec. Samples sit at
//   x(i) = origin + (i + offset) * dx,
// so offset = 0.5 on every axis gives the cell-centred grid, and offset 0 on axis a (with one more
// sample on that axis) gives the face grid that MacGrid stores for velocity component a.
// Storage is x-fastest, so loops over the last index outermost are cache friendly.
#include <algorithm>
#include <cassert>
#include <vector>

#include "msim/core/grid_spec.hpp"

namespace msim {

// The zero of a sample type: T{} for scalars, T::Zero() for Eigen vectors (whose T{} is
// uninitialised).
template <typename T>
T zeroOf() {
  if constexpr (requires { T::Zero(); })
    return T::Zero();
  else
    return T{};
}

template <typename T, int D>
class Grid {
 public:
  Grid() = default;
  // Cell-centred grid over spec.
  explicit Grid(const GridSpec<D>& spec, T value = zeroOf<T>())
      : Grid(spec, spec.res, Vec<D>::Constant(0.5), value) {}
  // General sampled grid: `samples` per axis at positions origin + (i + offset) * dx.
  Grid(const GridSpec<D>& spec, const IVec<D>& samples, const Vec<D>& offset, T value = zeroOf<T>())
      : spec_(spec), size_(samples), offset_(offset) {
    std::size_t n = 1;
    for (int a = 0; a < D; ++a) {
      stride_[a] = static_cast<std::ptrdiff_t>(n);
      n *= static_cast<std::size_t>(samples[a]);
    }
    data_.assign(n, value);
  }

  const GridSpec<D>& spec() const { return spec_; }
  const IVec<D>& size() const { return size_; }
  const Vec<D>& offset() const { return offset_; }
  std::size_t count() const { return data_.size(); }
  std::ptrdiff_t stride(int axis) const { return stride_[axis]; }

  std::size_t index(const IVec<D>& c) const {
    std::ptrdiff_t i = 0;
    for (int a = 0; a < D; ++a) {
      assert(c[a] >= 0 && c[a] < size_[a]);
      i += c[a] * stride_[a];
    }
    return static_cast<std::size_t>(i);
  }
  IVec<D> coord(std::size_t linear) const {
    IVec<D> c;
    for (int a = 0; a < D; ++a) {
      c[a] = static_cast<int>(linear % static_cast<std::size_t>(size_[a]));
      linear /= static_cast<std::size_t>(size_[a]);
    }
    return c;
  }
  bool inside(const IVec<D>& c) const {
    for (int a = 0; a < D; ++a)
      if (c[a] < 0 || c[a] >= size_[a]) return false;
    return true;
  }

  T& operator()(const IVec<D>& c) { return data_[index(c)]; }
  const T& operator()(const IVec<D>& c) const { return data_[index(c)]; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  // Sample at clamped coordinates: the boundary value extends outwards (zero-gradient).
  const T& clamped(IVec<D> c) const {
    for (int a = 0; a < D; ++a) c[a] = std::clamp(c[a], 0, size_[a] - 1);
    return data_[index(c)];
  }

  // World position of sample c.
  Vec<D> position(const IVec<D>& c) const {
    return spec_.origin + (c.template cast<double>() + offset_) * spec_.dx;
  }
  // Continuous sample coordinates of world point x (sample c sits at exactly c).
  Vec<D> toSampleSpace(const Vec<D>& x) const { return (x - spec_.origin) / spec_.dx - offset_; }

  std::vector<T>& data() { return data_; }
  const std::vector<T>& data() const { return data_; }
  void fill(T value) { std::fill(data_.begin(), data_.end(), value); }
  bool sameLayout(const Grid& o) const { return spec_ == o.spec_ && size_ == o.size_ && offset_ == o.offset_; }

 private:
  GridSpec<D> spec_;
  IVec<D> size_ = IVec<D>::Zero();
  Vec<D> offset_ = Vec<D>::Constant(0.5);
  std::ptrdiff_t stride_[D] = {};
  std::vector<T> data_;
};

}  // namespace msim
