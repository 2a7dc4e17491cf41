#include "msim/fluid/smoke/viscosity.hpp"

#include <algorithm>
#include <cmath>

#include "msim/core/parallel.hpp"

namespace msim::fluid {

namespace {

// The face-grid Laplacian of component `axis` times dx^2 at one sample, split into what the
// solvers need: sum over neighbours of (x_nb - x_i) plus the wall-ghost terms 2 (U - x_i), and the
// diagonal count k_i (so that -dx^2 lap = k_i x_i - sum x_nb - 2 U).
template <int D>
struct FaceStencil {
  const Grid<float, D>& grid;
  const ViscosityBoundaries<D>& b;
  int axis;

  // withWall = false gives the homogeneous operator (U = 0) the PCG iterates with.
  double laplace(const float* x, const IVec<D>& f, std::size_t lin, bool withWall) const {
    const double xi = x[lin];
    double sum = 0.0;
    for (int d = 0; d < D; ++d) {
      for (int s = 0; s < 2; ++s) {
        const int g = f[d] + (s ? 1 : -1);
        if (g >= 0 && g < grid.size()[d]) {
          sum += x[s ? lin + grid.stride(d) : lin - grid.stride(d)] - xi;
        } else if (noSlipGhost(d, s)) {
          sum += 2.0 * ((withWall ? b.wallVelocity[d][s][axis] : 0.0) - xi);
        }
      }
    }
    return sum;
  }
  int diagonal(const IVec<D>& f) const {
    int k = 0;
    for (int d = 0; d < D; ++d)
      for (int s = 0; s < 2; ++s) {
        const int g = f[d] + (s ? 1 : -1);
        if (g >= 0 && g < grid.size()[d]) k += 1;
        else if (noSlipGhost(d, s)) k += 2;
      }
    return k;
  }
  // Only a wall parallel to the component has a ghost sample half a cell outside; along the
  // component's own axis the boundary faces are samples (fixed on walls, zero gradient when open).
  bool noSlipGhost(int d, int s) const {
    return d != axis && b.slip == WallSlip::NoSlip && b.sides.side[d][s] == numerics::DomainSide::Wall;
  }
};

// The sums and norms of the solve over the samples this rank updates (all of them without a
// split), reduced over the ranks.
template <int D>
class OwnedReductions {
 public:
  OwnedReductions(const Grid<float, D>& layout, int axis, DomainSplit<D>* split) : layout_(layout), split_(split) {
    if (split) split->ownedSamples(IVec<D>::Unit(axis), lo_, hi_);
  }
  double maxAbs(const float* v) const {
    const double local = parallelMax(layout_.count(), [&](std::size_t i) { return own(i) ? std::abs(double(v[i])) : 0.0; });
    return split_ ? split_->maxOverRanks(local) : local;
  }
  double dot(const float* a, const float* b) const {
    const double local = parallelSum(layout_.count(), [&](std::size_t i) { return own(i) ? double(a[i]) * b[i] : 0.0; });
    return split_ ? split_->sumOverRanks(local) : local;
  }

 private:
  bool own(std::size_t i) const {
    if (!split_) return true;
    const IVec<D> s = layout_.coord(i);
    return (s.array() >= lo_.array()).all() && (s.array() < hi_.array()).all();
  }
  const Grid<float, D>& layout_;
  DomainSplit<D>* split_;
  IVec<D> lo_ = IVec<D>::Zero(), hi_ = IVec<D>::Zero();
};

}  // namespace

template <int D>
ViscousDiffusion<D>::ViscousDiffusion(const GridSpec<D>& spec) : spec_(spec) {
  std::size_t n = 0;
  for (int a = 0; a < D; ++a) {
    IVec<D> s = spec.res;
    s[a] += 1;
    std::size_t c = 1;
    for (int d = 0; d < D; ++d) c *= static_cast<std::size_t>(s[d]);
    n = std::max(n, c);
  }
  for (auto* v : {&old_, &r_, &z_, &p_, &q_}) v->assign(n, 0.0f);
}

template <int D>
int ViscousDiffusion<D>::apply(MacGrid<D>& velocity, const MacGrid<D>& faceWeights,
                               const ViscosityBoundaries<D>& boundaries, double nu, double dt, ViscosityMode mode,
                               const ViscositySolveSettings& settings, DomainSplit<D>* split) {
  const double c = nu * dt / (spec_.dx * spec_.dx);
  if (split) split->exchange(velocity);  // the stencils read the neighbours' faces
  int iterations = 0;
  for (int a = 0; a < D; ++a)
    iterations = std::max(iterations, solveComponent(a, velocity.component(a), faceWeights.component(a), boundaries,
                                                     c, mode, settings, split));
  if (split) split->exchange(velocity);
  return iterations;
}

template <int D>
int ViscousDiffusion<D>::solveComponent(int axis, Grid<float, D>& u, const Grid<float, D>& weight,
                                        const ViscosityBoundaries<D>& b, double c, ViscosityMode mode,
                                        const ViscositySolveSettings& settings, DomainSplit<D>* split) {
  const FaceStencil<D> st{u, b, axis};
  const std::size_t n = u.count();
  float* x = u.data().data();
  auto isFree = [&](std::size_t lin) { return weight[lin] > 0.0f; };

  if (mode == ViscosityMode::Explicit) {
    std::copy(x, x + n, old_.begin());
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      if (isFree(lin)) x[lin] = static_cast<float>(old_[lin] + c * st.laplace(old_.data(), f, lin, true));
    });
    return 0;
  }

  // Backward Euler: x - c L(x) = u*. Starting from x = u* the residual is c L(u*) (the explicit
  // increment); fixed faces carry no residual and no search direction, so they stay Dirichlet data.
  // Split: every product reads the direction's ghosts (filled first); the samples a rank does not
  // own are computed too, from whatever they hold, but no sum reads them.
  const OwnedReductions<D> owned(u, axis, split);
  Grid<float, D>& direction = directions_[static_cast<std::size_t>(axis)];
  if (split && !direction.sameLayout(u)) direction = Grid<float, D>(u.spec(), u.size(), u.offset());
  float* p = split ? direction.data().data() : p_.data();
  parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
    r_[lin] = isFree(lin) ? static_cast<float>(c * st.laplace(x, f, lin, true)) : 0.0f;
    z_[lin] = isFree(lin) ? static_cast<float>(r_[lin] / (1.0 + c * st.diagonal(f))) : 0.0f;
    p[lin] = z_[lin];
  });
  const double scale = std::max(owned.maxAbs(x), 1e-30);
  double rz = owned.dot(r_.data(), z_.data());
  int it = 0;
  while (it < settings.maxIterations && owned.maxAbs(r_.data()) > settings.tolerance * scale) {
    ++it;
    if (split) split->exchange(direction, axis);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      q_[lin] = isFree(lin) ? static_cast<float>(p[lin] - c * st.laplace(p, f, lin, false)) : 0.0f;
    });
    const double pq = owned.dot(p, q_.data());
    if (pq <= 0.0) break;
    const double alpha = rz / pq;
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      x[lin] += static_cast<float>(alpha * p[lin]);
      r_[lin] -= static_cast<float>(alpha * q_[lin]);
      z_[lin] = isFree(lin) ? static_cast<float>(r_[lin] / (1.0 + c * st.diagonal(f))) : 0.0f;
    });
    const double rzNew = owned.dot(r_.data(), z_.data());
    const double beta = rzNew / rz;
    rz = rzNew;
    parallelFor(0, n, [&](std::size_t i) { p[i] = static_cast<float>(z_[i] + beta * p[i]); });
  }
  return it;
}

template class ViscousDiffusion<2>;
template class ViscousDiffusion<3>;

}  // namespace msim::fluid
