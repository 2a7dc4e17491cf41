#pragma once
// IndexBox<D>: a box of integer indices [lo, hi) (hi exclusive on every axis): a block's cells in
// a grid split among processes, the cells a rank owns or stores.
#include "msim/core/vec.hpp"

namespace msim {

template <int D>
struct IndexBox {
  IVec<D> lo = IVec<D>::Zero();
  IVec<D> hi = IVec<D>::Zero();

  IVec<D> size() const { return (hi - lo).cwiseMax(0); }
  bool empty() const { return (hi.array() <= lo.array()).any(); }
  long long count() const {
    long long n = 1;
    for (int a = 0; a < D; ++a) n *= empty() ? 0 : hi[a] - lo[a];
    return n;
  }
  bool contains(const IVec<D>& c) const { return (c.array() >= lo.array()).all() && (c.array() < hi.array()).all(); }
  IndexBox intersect(const IndexBox& o) const { return {lo.cwiseMax(o.lo), hi.cwiseMin(o.hi)}; }
};

}  // namespace msim
