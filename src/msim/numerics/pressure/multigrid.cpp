#include "msim/numerics/pressure/multigrid.hpp"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

// 1D weight of coarse cell C in the linear prolongation to fine cell f: a fine cell lies at
// 1/4 of a coarse spacing from its parent I and 3/4 from the neighbour J on its side; with no
// neighbour (domain edge) the parent's value is used alone. The restriction uses the same weights
// (transposed), so R and P are exact transposes of each other.
inline float weight1D(int f, int C, int coarseCount) {
  const int I = f / 2;
  const int J = (f % 2 == 0) ? I - 1 : I + 1;
  const bool hasJ = J >= 0 && J < coarseCount;
  if (C == I) return hasJ ? 0.75f : 1.0f;
  return (C == J && hasJ) ? 0.25f : 0.0f;
}

// Cells per axis of the next coarser level: an odd count rounds up, its last coarse cell then
// covering one fine cell (and the domain side beyond it).
template <int D>
IVec<D> coarserResolution(const IVec<D>& res) {
  return ((res.array() + 1) / 2).matrix();
}

template <int D>
bool canCoarsen(const IVec<D>& res, int minCells) {
  for (int a = 0; a < D; ++a)
    if ((res[a] + 1) / 2 < minCells) return false;
  return true;
}

}  // namespace

template <int D>
MacGrid<D> coarsenFaceWeights(const MacGrid<D>& fine) {
  const GridSpec<D>& fs = fine.spec();
  const GridSpec<D> cs(fs.origin, 2.0 * fs.dx, coarserResolution<D>(fs.res));
  MacGrid<D> coarse(cs);
  constexpr int kSub = 1 << (D - 1);
  for (int a = 0; a < D; ++a) {
    const auto& wf = fine.component(a);
    auto& wc = coarse.component(a);
    parallelForCells(wc, [&](const IVec<D>& F, std::size_t lin) {
      // The fine faces the coarse face covers. Along an odd axis the last coarse cell holds one
      // fine cell: its upper side is the domain's (fine face res), and across it only the fine
      // faces that exist count.
      float sum = 0.0f;
      int count = 0;
      for (int m = 0; m < kSub; ++m) {
        IVec<D> f = 2 * F;
        f[a] = std::min(f[a], fs.res[a]);
        int bit = 0;
        for (int b = 0; b < D; ++b)
          if (b != a) f[b] += (m >> bit++) & 1;
        if (!wf.inside(f)) continue;
        sum += wf(f);
        ++count;
      }
      wc[lin] = count > 0 ? sum / static_cast<float>(count) : 0.0f;
    });
  }
  return coarse;
}

template <int D>
std::vector<float> coarsenDirichletDiagonal(const std::vector<float>& fine, const IVec<D>& fineRes) {
  if (fine.empty()) return {};
  const IVec<D> res = coarserResolution<D>(fineRes);
  std::size_t n = 1;
  for (int a = 0; a < D; ++a) n *= static_cast<std::size_t>(res[a]);
  std::vector<float> coarse(n, 0.0f);
  constexpr float kShare = 1.0f / (1 << (D - 1));
  parallelForCells<D>(res, [&](const IVec<D>& C, std::size_t lin) {
    float sum = 0.0f;
    for (int k = 0; k < (1 << D); ++k) {
      std::size_t f = 0, stride = 1;
      bool inside = true;
      for (int a = 0; a < D; ++a) {
        const int c = 2 * C[a] + ((k >> a) & 1);
        inside = inside && c < fineRes[a];  // the last coarse cell of an odd axis has one child
        f += static_cast<std::size_t>(c) * stride;
        stride *= static_cast<std::size_t>(fineRes[a]);
      }
      if (inside) sum += fine[f];
    }
    coarse[lin] = sum * kShare;
  });
  return coarse;
}

template <int D>
MultigridPreconditioner<D>::MultigridPreconditioner(const PoissonMatrix<D>& fine, const MacGrid<D>& fineFaceWeight,
                                                    const MultigridSettings& settings,
                                                    const std::vector<float>& fineDirichletDiagonal)
    : settings_(settings) {
  MacGrid<D> weights;
  const MacGrid<D>* current = &fineFaceWeight;
  std::vector<float> dirichlet = fineDirichletDiagonal;
  IVec<D> res = fine.res();
  int levels = 1;
  while (canCoarsen<D>(res, settings.coarsestMinCells)) {
    res = coarserResolution<D>(res);
    ++levels;
  }
  coarse_.reserve(levels - 1);  // matrices_ points into coarse_, which must not reallocate
  matrices_.push_back(&fine);
  for (int l = 1; l < levels; ++l) {
    dirichlet = coarsenDirichletDiagonal<D>(dirichlet, current->spec().res);
    weights = coarsenFaceWeights(*current);
    current = &weights;
    coarse_.emplace_back(weights, dirichlet);
    matrices_.push_back(&coarse_.back());
  }
  transfer_.resize(levels - 1);
  for (int l = 0; l + 1 < levels; ++l) {
    for (int a = 0; a < D; ++a) {
      const int nf = matrices_[l]->res()[a], nc = matrices_[l + 1]->res()[a];
      Transfer1D& t = transfer_[l][a];
      for (int f = 0; f < nf; ++f) {
        const int I = f / 2;
        const int J = (f % 2 == 0) ? I - 1 : I + 1;
        const bool hasJ = J >= 0 && J < nc;
        t.parent.push_back(I);
        t.parentWeight.push_back(weight1D(f, I, nc));
        t.side.push_back(hasJ ? J : I);
        t.sideWeight.push_back(hasJ ? weight1D(f, J, nc) : 0.0f);
      }
      for (int C = 0; C < nc; ++C) {
        std::array<int, 4> idx{};
        std::array<float, 4> w{};
        for (int k = 0; k < 4; ++k) {
          const int f = 2 * C - 1 + k;
          const bool inside = f >= 0 && f < nf;
          idx[k] = inside ? f : 2 * C;
          w[k] = inside ? weight1D(f, C, nc) : 0.0f;
        }
        t.fine.push_back(idx);
        t.fineWeight.push_back(w);
      }
    }
  }
  b_.resize(levels);
  x_.resize(levels);
  r_.resize(levels);
  for (int l = 0; l < levels; ++l) {
    const std::size_t n = matrices_[l]->size();
    r_[l].assign(n, 0.0f);
    if (l > 0) {
      b_[l].assign(n, 0.0f);
      x_[l].assign(n, 0.0f);
    }
  }
  findBands();
}

template <int D>
void MultigridPreconditioner<D>::apply(const std::vector<float>& r, std::vector<float>& z) {
  vcycle(0, r, z);
}

template <int D>
void MultigridPreconditioner<D>::smooth(int level, const std::vector<float>& b, std::vector<float>& x, int first,
                                        int sweeps) {
  for (int s = 0; s < sweeps; ++s) matrices_[level]->gaussSeidelPair(b, x, first);
}

template <int D>
void MultigridPreconditioner<D>::smoothBand(int level, const std::vector<float>& b, std::vector<float>& x, int first) {
  const auto& band = band_[level];
  if (band[0].empty() && band[1].empty()) return;
  for (int s = 0; s < settings_.boundarySweeps; ++s) {
    matrices_[level]->relaxCells(b, x, band[first]);
    matrices_[level]->relaxCells(b, x, band[1 - first]);
  }
}

template <int D>
void MultigridPreconditioner<D>::findBands() {
  band_.assign(matrices_.size() - 1, {});
  for (std::size_t l = 0; l + 1 < matrices_.size(); ++l) {
    const PoissonMatrix<D>& A = *matrices_[l];
    const IVec<D> res = A.res();
    const std::size_t n = A.size();
    // Distance in face steps from a fluid cell with a partly or fully closed interior face
    // (domain walls do not count: plain multigrid handles them).
    std::vector<int> distance(n, -1);
    std::vector<std::size_t> front;
    auto coords = [&](std::size_t i) {
      IVec<D> c;
      for (int a = 0; a < D; ++a) {
        c[a] = static_cast<int>(i % static_cast<std::size_t>(res[a]));
        i /= static_cast<std::size_t>(res[a]);
      }
      return c;
    };
    for (std::size_t i = 0; i < n; ++i) {
      if (!(A.diag()[i] > 0.0f)) continue;
      const IVec<D> c = coords(i);
      bool near = false;
      for (int a = 0; a < D && !near; ++a) {
        near = (c[a] > 0 && A.lowerWeight(a)[i] < 1.0f) ||
               (c[a] + 1 < res[a] && A.lowerWeight(a)[i + A.stride(a)] < 1.0f);
      }
      if (near) distance[i] = 0, front.push_back(i);
    }
    for (int d = 1; d <= settings_.boundaryBand; ++d) {
      std::vector<std::size_t> next;
      for (const std::size_t i : front) {
        const IVec<D> c = coords(i);
        for (int a = 0; a < D; ++a)
          for (int step : {-1, 1}) {
            if (c[a] + step < 0 || c[a] + step >= res[a]) continue;
            const std::size_t j = step < 0 ? i - A.stride(a) : i + A.stride(a);
            if (distance[j] >= 0 || !(A.diag()[j] > 0.0f)) continue;
            distance[j] = d;
            next.push_back(j);
          }
      }
      front = std::move(next);
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (distance[i] < 0) continue;
      const IVec<D> c = coords(i);
      band_[l][c.sum() & 1].push_back(i);
    }
  }
}

template <int D>
void MultigridPreconditioner<D>::vcycle(int level, const std::vector<float>& b, std::vector<float>& x) {
  const PoissonMatrix<D>& A = *matrices_[level];
  std::fill(x.begin(), x.end(), 0.0f);
  if (level + 1 == levelCount()) {
    // Red, then (black, red) pairs: a palindrome, hence a symmetric approximate inverse.
    A.gaussSeidel(b, x, 0);
    for (int s = 0; s < settings_.coarsestSweeps; ++s) {
      A.gaussSeidel(b, x, 1);
      A.gaussSeidel(b, x, 0);
    }
    return;
  }
  // Interior then band before the coarse correction, band then interior after it, each with the
  // colours reversed: the mirror image, so the V-cycle stays symmetric.
  smooth(level, b, x, 0, settings_.smoothingSweeps);
  smoothBand(level, b, x, 0);
  A.residual(b, x, r_[level]);
  restrictResidual(level);
  vcycle(level + 1, b_[level + 1], x_[level + 1]);
  prolongAdd(level, x);
  smoothBand(level, b, x, 1);
  smooth(level, b, x, 1, settings_.smoothingSweeps);
}

template <int D>
void MultigridPreconditioner<D>::restrictResidual(int fineLevel) {
  const PoissonMatrix<D>& fine = *matrices_[fineLevel];
  const PoissonMatrix<D>& coarse = *matrices_[fineLevel + 1];
  const auto& t = transfer_[fineLevel];
  const std::vector<float>& r = r_[fineLevel];
  std::vector<float>& b = b_[fineLevel + 1];
  constexpr float kScale = 4.0f / (1 << D);
  parallelForCells<D>(coarse.res(), [&](const IVec<D>& C, std::size_t lin) {
    if (coarse.diag()[lin] <= 0.0f) {
      b[lin] = 0.0f;
      return;
    }
    const auto& fx = t[0].fine[C[0]];
    const auto& wx = t[0].fineWeight[C[0]];
    float sum = 0.0f;
    if constexpr (D == 2) {
      for (int j = 0; j < 4; ++j) {
        const float* row = r.data() + static_cast<std::size_t>(t[1].fine[C[1]][j]) * fine.stride(1);
        float s = 0.0f;
        for (int i = 0; i < 4; ++i) s += wx[i] * row[fx[i]];
        sum += t[1].fineWeight[C[1]][j] * s;
      }
    } else {
      for (int k = 0; k < 4; ++k) {
        const std::size_t zk = static_cast<std::size_t>(t[2].fine[C[2]][k]) * fine.stride(2);
        float sk = 0.0f;
        for (int j = 0; j < 4; ++j) {
          const float* row = r.data() + zk + static_cast<std::size_t>(t[1].fine[C[1]][j]) * fine.stride(1);
          float s = 0.0f;
          for (int i = 0; i < 4; ++i) s += wx[i] * row[fx[i]];
          sk += t[1].fineWeight[C[1]][j] * s;
        }
        sum += t[2].fineWeight[C[2]][k] * sk;
      }
    }
    b[lin] = kScale * sum;
  });
}

template <int D>
void MultigridPreconditioner<D>::prolongAdd(int fineLevel, std::vector<float>& fineX) {
  const PoissonMatrix<D>& fine = *matrices_[fineLevel];
  const PoissonMatrix<D>& coarse = *matrices_[fineLevel + 1];
  const auto& t = transfer_[fineLevel];
  const float* xc = x_[fineLevel + 1].data();
  const IVec<D>& res = fine.res();
  const int nfx = res[0], ncx = coarse.res()[0];
  std::size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= static_cast<std::size_t>(res[a]);
  // Per fine row: first blend the 2^(D-1) coarse rows it reads along y (and z) into one coarse
  // row (contiguous, vectorised), then interpolate that along x. Per cell this is 2 reads instead
  // of 2^D table-driven ones.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 8), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<float> blended(static_cast<std::size_t>(ncx));
    for (std::size_t row = r.begin(); row != r.end(); ++row) {
      int f[D] = {};
      std::size_t rest = row;
      for (int a = 1; a < D; ++a) {
        f[a] = static_cast<int>(rest % static_cast<std::size_t>(res[a]));
        rest /= static_cast<std::size_t>(res[a]);
      }
      constexpr int kRows = 1 << (D - 1);
      const float* src[kRows];
      float w[kRows];
      for (int m = 0; m < kRows; ++m) {
        std::size_t base = 0;
        w[m] = 1.0f;
        for (int a = 1; a < D; ++a) {
          const bool side = (m >> (a - 1)) & 1;
          base += static_cast<std::size_t>(side ? t[a].side[f[a]] : t[a].parent[f[a]]) * coarse.stride(a);
          w[m] *= side ? t[a].sideWeight[f[a]] : t[a].parentWeight[f[a]];
        }
        src[m] = xc + base;
      }
      for (int i = 0; i < ncx; ++i) {
        float v = 0.0f;
        for (int m = 0; m < kRows; ++m) v += w[m] * src[m][i];
        blended[i] = v;
      }
      const std::size_t lin = row * static_cast<std::size_t>(nfx);
      const float* diag = fine.diag().data() + lin;
      float* out = fineX.data() + lin;
      for (int i = 0; i < nfx; ++i) {
        const float v = t[0].parentWeight[i] * blended[t[0].parent[i]] + t[0].sideWeight[i] * blended[t[0].side[i]];
        out[i] += diag[i] > 0.0f ? v : 0.0f;  // excluded cells stay at 0
      }
    }
  });
}

template MacGrid<2> coarsenFaceWeights<2>(const MacGrid<2>&);
template MacGrid<3> coarsenFaceWeights<3>(const MacGrid<3>&);
template std::vector<float> coarsenDirichletDiagonal<2>(const std::vector<float>&, const IVec<2>&);
template std::vector<float> coarsenDirichletDiagonal<3>(const std::vector<float>&, const IVec<3>&);
template class MultigridPreconditioner<2>;
template class MultigridPreconditioner<3>;

}  // namespace msim::numerics
