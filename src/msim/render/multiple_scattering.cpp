#include "msim/render/multiple_scattering.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim::render {
namespace {

// The system of every level is kept in conductance form divided by h_fine^(D-2), so its entries are
// O(1) in 2D and 3D: a coupling kappa_f, absorption sigma_a rho h^2, source q0 h^2 on the finest
// level. Unknowns and the arithmetic of the relaxations are double: where kappa is large (thin
// medium) the diagonal exceeds the absorption by orders of magnitude, and the rounding of float
// unknowns would put a floor on the residual near the default tolerance.
template <int D>
struct Level {
  IVec<D> res;
  std::array<std::ptrdiff_t, D> stride{};  // of the padded layout: one ghost cell on every side,
                                           // whose couplings and unknowns stay 0 (no bounds tests)
  std::array<std::vector<float>, D> coupling;  // between c and c + e_a; 0 unless both are medium
  std::vector<float> sink;                     // absorption + Marshak leakage; 1 in empty cells
  std::vector<unsigned char> active;           // medium cells
  std::vector<float> b;
  std::vector<double> x;
  // Per row of x-cells, the span [begin, end) holding its medium cells: sweeps skip the empty air
  // around the medium (most of a smoke domain), whose unknowns stay 0.
  std::vector<int> begin, end;

  explicit Level(const IVec<D>& r) : res(r) {
    std::size_t n = 1;
    for (int a = 0; a < D; ++a) {
      stride[a] = static_cast<std::ptrdiff_t>(n);
      n *= static_cast<std::size_t>(r[a] + 2);
    }
    for (auto& g : coupling) g.assign(n, 0.0f);
    sink.assign(n, 0.0f);
    active.assign(n, 0);
    b.assign(n, 0.0f);
    x.assign(n, 0.0);
    begin.assign(static_cast<std::size_t>(rows()), 0);
    end.assign(static_cast<std::size_t>(rows()), 0);
  }
  void findSpans() {
    tbb::parallel_for(0, rows(), [&](int row) {
      const std::size_t start = index(rowStart(row));
      int lo = res[0], hi = 0;
      for (int i = 0; i < res[0]; ++i)
        if (active[start + static_cast<std::size_t>(i)]) {
          lo = std::min(lo, i);
          hi = i + 1;
        }
      begin[static_cast<std::size_t>(row)] = std::min(lo, hi);
      end[static_cast<std::size_t>(row)] = hi;
    });
  }
  std::size_t index(const IVec<D>& c) const {
    std::ptrdiff_t i = 0;
    for (int a = 0; a < D; ++a) i += (c[a] + 1) * stride[a];
    return static_cast<std::size_t>(i);
  }
  int rows() const {
    int n = 1;
    for (int a = 1; a < D; ++a) n *= res[a];
    return n;
  }
  IVec<D> rowStart(int row) const {
    IVec<D> c = IVec<D>::Zero();
    if constexpr (D == 2) {
      c[1] = row;
    } else {
      c[1] = row % res[1];
      c[2] = row / res[1];
    }
    return c;
  }
  // (A x)_c subtracted from b_c.
  double residual(std::size_t c) const {
    double r = b[c] - sink[c] * x[c];
    for (int a = 0; a < D; ++a)
      r -= coupling[a][c] * (x[c] - x[c + stride[a]]) + coupling[a][c - stride[a]] * (x[c] - x[c - stride[a]]);
    return r;
  }
};

// f(first cell of the row, padded index of that cell, medium span begin, end) for every row of
// x-cells holding medium, in parallel.
template <int D, typename F>
void forRows(const Level<D>& level, F&& f) {
  tbb::parallel_for(tbb::blocked_range<int>(0, level.rows(), 8), [&](const tbb::blocked_range<int>& range) {
    for (int row = range.begin(); row != range.end(); ++row) {
      const auto r = static_cast<std::size_t>(row);
      if (level.begin[r] == level.end[r]) continue;
      const IVec<D> c0 = level.rowStart(row);
      f(c0, level.index(c0), level.begin[r], level.end[r]);
    }
  });
}

// One Gauss-Seidel half-sweep over the cells whose coordinate sum has parity `colour`: cells of one
// colour couple only to the other colour, so they update independently (in parallel).
template <int D>
void relax(Level<D>& L, int colour) {
  forRows(L, [&](const IVec<D>& c0, std::size_t row, int begin, int end) {
    int parity = 0;
    for (int a = 1; a < D; ++a) parity += c0[a];
    for (int i = begin + ((begin + colour + parity) & 1); i < end; i += 2) {
      const std::size_t c = row + static_cast<std::size_t>(i);
      double sum = L.b[c], diagonal = L.sink[c];
      for (int a = 0; a < D; ++a) {
        const double up = L.coupling[a][c], down = L.coupling[a][c - L.stride[a]];
        sum += up * L.x[c + L.stride[a]] + down * L.x[c - L.stride[a]];
        diagonal += up + down;
      }
      L.x[c] = sum / diagonal;
    }
  });
}

template <int D>
double residualNormSquared(const Level<D>& L) {
  return parallelSum(static_cast<std::size_t>(L.rows()), [&](std::size_t row) {
    const std::size_t start = L.index(L.rowStart(static_cast<int>(row)));
    double s = 0.0;
    for (int i = L.begin[row]; i < L.end[row]; ++i) {
      const double r = L.residual(start + static_cast<std::size_t>(i));
      s += r * r;
    }
    return s;
  });
}

// Children of coarse cell C: fine cells 2C + o, o in {0,1}^D, inside the fine grid.
template <int D, typename F>
void forChildren(const Level<D>& fine, const IVec<D>& C, F&& f) {
  for (int o = 0; o < (1 << D); ++o) {
    IVec<D> child = 2 * C;
    bool inside = true;
    for (int a = 0; a < D; ++a) {
      child[a] += (o >> a) & 1;
      inside = inside && child[a] < fine.res[a];
    }
    if (inside) f(o, fine.index(child));
  }
}

// The coarse operator: a coarse cell is medium if any child is; the coupling across a coarse face
// is half the sum of the fine couplings on it (two fine half-paths in series per coarse path: exact
// for constant kappa), absorption and leakage through Marshak faces are summed over the children.
template <int D>
void coarsenOperator(const Level<D>& fine, Level<D>& coarse) {
  parallelForCells<D>(coarse.res, [&](const IVec<D>& C, std::size_t) {
    const std::size_t i = coarse.index(C);
    double sink = 0.0;
    std::array<double, D> coupling{};
    bool medium = false;
    forChildren(fine, C, [&](int o, std::size_t f) {
      if (!fine.active[f]) return;
      medium = true;
      sink += fine.sink[f];
      for (int a = 0; a < D; ++a)
        if ((o >> a) & 1) coupling[a] += fine.coupling[a][f];
    });
    coarse.active[i] = medium;
    coarse.sink[i] = medium ? static_cast<float>(sink) : 1.0f;
    for (int a = 0; a < D; ++a) coarse.coupling[a][i] = static_cast<float>(0.5 * coupling[a]);
  });
}

// b_coarse = sum of the children's residuals (the residual is a power: it adds up); x_coarse = 0.
template <int D>
void restrictResidual(const Level<D>& fine, Level<D>& coarse) {
  forRows(coarse, [&](const IVec<D>& c0, std::size_t row, int begin, int end) {
    IVec<D> C = c0;
    for (C[0] = begin; C[0] < end; ++C[0]) {
      double r = 0.0;
      forChildren(fine, C, [&](int, std::size_t f) { r += fine.residual(f); });
      const std::size_t i = row + static_cast<std::size_t>(C[0]);
      coarse.b[i] = static_cast<float>(r);
      coarse.x[i] = 0.0;
    }
  });
}

// x_fine += (bi/tri)linear interpolation of x_coarse between cell centres (weights 3/4 and 1/4 per
// axis), over the medium coarse cells only, renormalised: near the medium boundary the correction
// extends the medium's instead of blending in the zero of the empty cells.
template <int D>
void prolongAdd(const Level<D>& coarse, Level<D>& fine) {
  forRows(fine, [&](const IVec<D>& c0, std::size_t row, int begin, int end) {
    IVec<D> f = c0;
    for (int i = begin; i < end; ++i) {
      const std::size_t fi = row + static_cast<std::size_t>(i);
      if (!fine.active[fi]) continue;
      f[0] = i;
      IVec<D> parent, side;
      for (int a = 0; a < D; ++a) {
        parent[a] = f[a] / 2;
        side[a] = (f[a] & 1) ? 1 : -1;
      }
      const std::size_t p = coarse.index(parent);  // sides -1 and res land in the ghost layer
      double sum = 0.0, weight = 0.0;
      for (int o = 0; o < (1 << D); ++o) {
        std::ptrdiff_t ci = static_cast<std::ptrdiff_t>(p);
        double w = 1.0;
        for (int a = 0; a < D; ++a) {
          const bool toSide = (o >> a) & 1;
          ci += toSide ? side[a] * coarse.stride[a] : 0;
          w *= toSide ? 0.25 : 0.75;
        }
        if (!coarse.active[static_cast<std::size_t>(ci)]) continue;
        sum += w * coarse.x[static_cast<std::size_t>(ci)];
        weight += w;
      }
      fine.x[fi] += sum / weight;  // the parent is medium, so weight >= (3/4)^D
    }
  });
}

// The faces of cell c of the finest grid (all but the reflecting domain faces): f(axis, side,
// linear index of the medium neighbour or -1 for a Marshak face).
template <int D, typename F>
void forFaces(const Grid<float, D>& density, const IVec<D>& c, const DiffusionSettings& settings, F&& f) {
  for (int a = 0; a < D; ++a)
    for (int side = -1; side <= 1; side += 2) {
      IVec<D> n = c;
      n[a] += side;
      if (n[a] < 0 || n[a] >= density.size()[a]) {
        if (!settings.reflectingAxes[a]) f(a, side, std::ptrdiff_t(-1));
        continue;
      }
      const std::size_t ni = density.index(n);
      f(a, side, density[ni] > settings.minDensity ? static_cast<std::ptrdiff_t>(ni) : std::ptrdiff_t(-1));
    }
}

template <int D>
class Solver {
 public:
  Solver(const Grid<float, D>& density, const Grid<float, D>& source, const Grid<Vecf<D>, D>* flux,
         const DiffusionMedium& medium, const DiffusionSettings& settings)
      : density_(density), source_(source), flux_(flux), settings_(settings), h_(density.spec().dx),
        sigmaTr_(medium.extinction * (1.0 - medium.albedo * medium.phaseG)),
        sigmaA_(medium.extinction * (1.0 - medium.albedo)) {
    levels_.emplace_back(density.size());
    buildFinest();
    levels_.front().findSpans();
    // Coarsen down to <= 4 cells per axis (ceil halving; an axis of 1 cell stays 1).
    while (levels_.back().res.maxCoeff() > 4) {
      const IVec<D> res = (levels_.back().res.array() + 1) / 2;
      levels_.emplace_back(res);
      coarsenOperator(levels_[levels_.size() - 2], levels_.back());
      levels_.back().findSpans();
    }
    factorCoarsest();
  }

  Grid<float, D> solve(DiffusionStats* stats) {
    Level<D>& L = levels_.front();
    const double bNorm = std::sqrt(parallelSum(L.b.size(), [&](std::size_t i) { return double(L.b[i]) * L.b[i]; }));
    int cycles = 0;
    double relative = 0.0;
    if (bNorm > 0.0) {
      for (;;) {
        relative = std::sqrt(residualNormSquared(L)) / bNorm;
        if (relative <= settings_.tolerance || cycles >= settings_.maxCycles) break;
        vcycle(0);
        ++cycles;
      }
    }
    Grid<float, D> fluence(density_.spec());
    parallelForCells<D>(L.res, [&](const IVec<D>& c, std::size_t lin) {
      fluence[lin] = static_cast<float>(L.x[L.index(c)]);
    });
    if (stats) {
      stats->cycles = cycles;
      stats->relativeResidual = relative;
      balance(fluence, *stats);
    }
    return fluence;
  }

 private:
  double kappa(double rho) const { return 1.0 / (3.0 * sigmaTr_ * rho); }
  bool medium(std::size_t lin) const { return density_[lin] > settings_.minDensity; }
  // w = q1 / (sigma_tr rho) on a face between cells i and j (j = -1: the face of i alone).
  double faceFlux(std::size_t i, std::ptrdiff_t j, int axis) const {
    if (!flux_) return 0.0;
    if (j < 0) return (*flux_)[i][axis] / (sigmaTr_ * density_[i]);
    const auto n = static_cast<std::size_t>(j);
    return (double((*flux_)[i][axis]) + (*flux_)[n][axis]) / (sigmaTr_ * (double(density_[i]) + density_[n]));
  }

  void buildFinest() {
    Level<D>& L = levels_.front();
    const double h = h_;
    parallelForCells<D>(L.res, [&](const IVec<D>& c, std::size_t lin) {
      const std::size_t i = L.index(c);
      if (!medium(lin)) {
        L.sink[i] = 1.0f;  // empty air: the row reads x = 0
        return;
      }
      L.active[i] = 1;
      const double rho = density_[lin], k = kappa(rho);
      double sink = sigmaA_ * rho * h * h, rhs = source_[lin] * h * h;
      forFaces(density_, c, settings_, [&](int a, int side, std::ptrdiff_t n) {
        if (n >= 0) {
          // kappa at the face from the mean density (harmonic mean of the two kappas).
          if (side > 0) L.coupling[a][i] = static_cast<float>(kappa(0.5 * (rho + density_[std::size_t(n)])));
          rhs -= side * h * faceFlux(lin, n, a);
        } else {
          // Marshak face (5.24): outgoing flux (2 kappa phi_c + h w.n) / (h + 4 kappa) per area.
          sink += h * 2.0 * k / (h + 4.0 * k);
          rhs -= side * h * h * faceFlux(lin, -1, a) / (h + 4.0 * k);
        }
      });
      L.sink[i] = static_cast<float>(sink);
      L.b[i] = static_cast<float>(rhs);
    });
  }

  // Dense LDL^T of the coarsest level (<= 4^D unknowns), factored once per solve.
  void factorCoarsest() {
    const Level<D>& L = levels_.back();
    const int n = static_cast<int>(L.res.prod());
    coarseIndex_.resize(n);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    for (int k = 0; k < n; ++k) {
      IVec<D> c;
      int rest = k;
      for (int a = 0; a < D; ++a) {
        c[a] = rest % L.res[a];
        rest /= L.res[a];
      }
      coarseIndex_[k] = L.index(c);
    }
    for (int k = 0; k < n; ++k) {
      const std::size_t i = coarseIndex_[k];
      A(k, k) += L.sink[i];
      int step = 1;
      for (int a = 0; a < D; ++a) {
        if ((k / step) % L.res[a] + 1 < L.res[a]) {
          const double g = L.coupling[a][i];
          A(k, k) += g;
          A(k + step, k + step) += g;
          A(k, k + step) = A(k + step, k) = -g;
        }
        step *= L.res[a];
      }
    }
    coarseSolver_.compute(A);
    coarseRhs_.resize(n);
  }

  void vcycle(std::size_t l) {
    Level<D>& L = levels_[l];
    if (l + 1 == levels_.size()) {
      for (Eigen::Index k = 0; k < coarseRhs_.size(); ++k) coarseRhs_[k] = L.b[coarseIndex_[k]];
      coarseSolver_.solveInPlace(coarseRhs_);
      for (Eigen::Index k = 0; k < coarseRhs_.size(); ++k) L.x[coarseIndex_[k]] = coarseRhs_[k];
      return;
    }
    for (int s = 0; s < settings_.relaxations; ++s) {
      relax(L, 0);
      relax(L, 1);
    }
    restrictResidual(L, levels_[l + 1]);
    vcycle(l + 1);
    prolongAdd(levels_[l + 1], L);
    for (int s = 0; s < settings_.relaxations; ++s) {
      relax(L, 1);
      relax(L, 0);
    }
  }

  // The energy balance recomputed from the solution in physical units: cell volume h^D, face area
  // h^(D-1).
  void balance(const Grid<float, D>& phi, DiffusionStats& stats) const {
    const double h = h_, volume = std::pow(h, D), area = std::pow(h, D - 1);
    const std::size_t n = phi.count();
    stats.sourcePower = volume * parallelSum(n, [&](std::size_t i) { return medium(i) ? double(source_[i]) : 0.0; });
    stats.absorbedPower =
        volume * parallelSum(n, [&](std::size_t i) { return medium(i) ? sigmaA_ * density_[i] * phi[i] : 0.0; });
    stats.escapedPower = area * parallelSum(n, [&](std::size_t i) {
      if (!medium(i)) return 0.0;
      const double k = kappa(density_[i]);
      double out = 0.0;
      forFaces(density_, phi.coord(i), settings_, [&](int a, int side, std::ptrdiff_t nb) {
        if (nb < 0) out += (2.0 * k * phi[i] + h * side * faceFlux(i, -1, a)) / (h + 4.0 * k);
      });
      return out;
    });
  }

  const Grid<float, D>& density_;
  const Grid<float, D>& source_;
  const Grid<Vecf<D>, D>* flux_;
  DiffusionSettings settings_;
  double h_, sigmaTr_, sigmaA_;
  std::vector<Level<D>> levels_;
  std::vector<std::size_t> coarseIndex_;  // padded index of each unknown of the dense solve
  Eigen::LDLT<Eigen::MatrixXd> coarseSolver_;
  Eigen::VectorXd coarseRhs_;
};

}  // namespace

template <int D>
Grid<float, D> solveMultipleScattering(const Grid<float, D>& density, const Grid<float, D>& source,
                                       const DiffusionMedium& medium, const DiffusionSettings& settings,
                                       DiffusionStats* stats, const Grid<Vecf<D>, D>* sourceFlux) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("solveMultipleScattering: " + what); };
  if (density.size() != density.spec().res || density.offset() != Vec<D>::Constant(0.5))
    fail("density must be a cell-centred grid");
  if (!source.sameLayout(density)) fail("source and density grids differ in layout");
  if (sourceFlux && (sourceFlux->spec() != density.spec() || sourceFlux->size() != density.size() ||
                     sourceFlux->offset() != density.offset()))
    fail("sourceFlux and density grids differ in layout");
  if (!(medium.extinction > 0.0) || !std::isfinite(medium.extinction)) fail("extinction must be positive and finite");
  if (!(medium.albedo >= 0.0 && medium.albedo <= 1.0)) fail("albedo must lie in [0, 1]");
  if (!(medium.phaseG > -1.0 && medium.phaseG < 1.0)) fail("phaseG must lie in (-1, 1)");
  if (settings.relaxations < 1 || settings.maxCycles < 0) fail("relaxations must be >= 1 and maxCycles >= 0");
  if (!(settings.minDensity >= 0.0)) fail("minDensity must be >= 0");
  Solver<D> solver(density, source, sourceFlux, medium, settings);
  return solver.solve(stats);
}

template Grid<float, 2> solveMultipleScattering<2>(const Grid<float, 2>&, const Grid<float, 2>&, const DiffusionMedium&,
                                                   const DiffusionSettings&, DiffusionStats*, const Grid<Vecf<2>, 2>*);
template Grid<float, 3> solveMultipleScattering<3>(const Grid<float, 3>&, const Grid<float, 3>&, const DiffusionMedium&,
                                                   const DiffusionSettings&, DiffusionStats*, const Grid<Vecf<3>, 3>*);

}  // namespace msim::render
