#include "msim/fluid/vortex/vortex_force.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "msim/core/parallel.hpp"

namespace msim::fluid {

namespace {

// Slabs of the slowest axis per task. The partition is fixed (not tied to the thread count), and
// each face belongs to one task, which adds the particles in index order: the result is the same
// on any number of threads.
constexpr int kSlabsPerTask = 4;

// Component a of (omega x d), the direction of F_p times |d| (N_p x omega = (omega x d) / |d|):
// in 2D omega = omega_z e_z, so omega x d = omega_z (-d_y, d_x).
template <int D>
double omegaCrossOffset(const VortexVector<D>& omega, const double* d, int a) {
  if constexpr (D == 3) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    return omega[b] * d[c] - omega[c] * d[b];
  } else {
    return a == 0 ? -omega[0] * d[1] : omega[0] * d[0];
  }
}

// Adds dt F_a of every particle to the faces of component a in slabs [kBegin, kEnd) of the slowest
// axis. Per particle, the offsets to the faces along each axis and the separable Gaussian factors
// exp(-d_b^2 / 2r^2) are tabulated once (in `table`, the task's reused storage), so the inner loop
// has one square root and no exponential per face.
template <int D>
void addToSlabs(const VortexParticles<D>& particles, VortexKernel kernel, double dt, int a, int kBegin, int kEnd,
                Grid<float, D>& faces, const Grid<float, D>* solid, const BlockPlacement<D>& placement,
                std::vector<double>& table) {
  const GridSpec<D>& spec = faces.spec();
  const double dx = spec.dx;
  const auto& x = particles.positions();
  const auto& omega = particles.vorticities();
  const auto& radius = particles.radii();
  const auto& strength = particles.strengths();
  constexpr int slow = D - 1;
  const bool gaussian = kernel == VortexKernel::ClampedGaussian;
  float* data = faces.data().data();

  // Interior faces only: the domain walls belong to the projection; faces next to solids get none.
  // On a block the walls are the global domain's, and ghost faces beyond them get none either.
  const int wallLo = placement.whole() ? 0 : -placement.cellOrigin[a];
  const int wallHi = placement.whole() ? spec.res[a] : placement.globalRes[a] - placement.cellOrigin[a];
  auto receivesForce = [&](const IVec<D>& f) {
    if (f[a] <= wallLo || f[a] >= wallHi) return false;
    if (!solid) return true;
    IVec<D> left = f;
    left[a] -= 1;
    return (*solid)(left) <= 0.5f && (*solid)(f) <= 0.5f;
  };

  for (std::size_t p = 0; p < x.size(); ++p) {
    const double r = radius[p], r2 = r * r;
    const Vec<D> s = faces.toSampleSpace(x[p].template cast<double>());
    IVec<D> lo, hi;
    for (int b = 0; b < D; ++b) {
      lo[b] = std::max(0, static_cast<int>(std::ceil(s[b] - r / dx)));
      hi[b] = std::min(faces.size()[b] - 1, static_cast<int>(std::floor(s[b] + r / dx)));
    }
    lo[slow] = std::max(lo[slow], kBegin);
    hi[slow] = std::min(hi[slow], kEnd - 1);
    bool empty = false;
    for (int b = 0; b < D; ++b) empty = empty || lo[b] > hi[b];
    if (empty) continue;

    // offset[b][i - lo[b]] = world offset of sample i from the particle along b; gauss likewise.
    std::size_t needed = 0;
    for (int b = 0; b < D; ++b) needed += 2 * static_cast<std::size_t>(hi[b] - lo[b] + 1);
    if (table.size() < needed) table.resize(needed);
    double* offset[D];
    double* gauss[D];
    double* next = table.data();
    for (int b = 0; b < D; ++b) {
      const int n = hi[b] - lo[b] + 1;
      offset[b] = next;
      gauss[b] = next + n;
      next += 2 * n;
      for (int i = 0; i < n; ++i) {
        const double d = (lo[b] + i - s[b]) * dx;
        offset[b][i] = d;
        gauss[b][i] = gaussian ? std::exp(-d * d / (2.0 * r2)) : 1.0;
      }
    }
    const double scale = dt * strength[p] * vortexKernelNormalisation<D>(kernel, r);

    IVec<D> f;
    double d[D];
    // One row along axis 0 at fixed outer indices: only the chord of the ball (widened by a sample
    // against rounding; the d^2 <= r^2 test below decides).
    auto row = [&](double outer2, double outerGauss) {
      const double rest = r2 - outer2;
      if (rest < 0.0) return;
      const double half = std::sqrt(rest) / dx;
      const int i0 = std::max(lo[0], static_cast<int>(std::ceil(s[0] - half)) - 1);
      const int i1 = std::min(hi[0], static_cast<int>(std::floor(s[0] + half)) + 1);
      for (f[0] = i0; f[0] <= i1; ++f[0]) {
        d[0] = offset[0][f[0] - lo[0]];
        const double dist2 = outer2 + d[0] * d[0];
        if (dist2 > r2 || dist2 == 0.0) continue;  // outside the support; N_p undefined at x_p (F = 0)
        if (!receivesForce(f)) continue;
        const double dist = std::sqrt(dist2);
        const double shape = gaussian ? outerGauss * gauss[0][f[0] - lo[0]] : 1.0 - dist / r;
        data[faces.index(f)] += static_cast<float>(scale * shape / dist * omegaCrossOffset<D>(omega[p], d, a));
      }
    };
    if constexpr (D == 2) {
      for (f[1] = lo[1]; f[1] <= hi[1]; ++f[1]) {
        d[1] = offset[1][f[1] - lo[1]];
        row(d[1] * d[1], gauss[1][f[1] - lo[1]]);
      }
    } else {
      for (f[2] = lo[2]; f[2] <= hi[2]; ++f[2]) {
        d[2] = offset[2][f[2] - lo[2]];
        for (f[1] = lo[1]; f[1] <= hi[1]; ++f[1]) {
          d[1] = offset[1][f[1] - lo[1]];
          row(d[1] * d[1] + d[2] * d[2], gauss[1][f[1] - lo[1]] * gauss[2][f[2] - lo[2]]);
        }
      }
    }
  }
}

}  // namespace

template <int D>
void addVortexForce(const VortexParticles<D>& particles, VortexKernel kernel, double dt, MacGrid<D>& velocity,
                    const Grid<float, D>* solid, const BlockPlacement<D>& placement) {
  requireValidVortexTimestep(dt, "addVortexForce");
  if (solid && !(solid->spec() == velocity.spec() && solid->size() == velocity.spec().res))
    throw std::invalid_argument("addVortexForce: the solid mask is not cell-centred on the velocity's grid");
  if (particles.empty() || dt == 0.0) return;
  for (int a = 0; a < D; ++a) {
    Grid<float, D>& faces = velocity.component(a);
    const int slabs = faces.size()[D - 1];
    const std::size_t tasks = static_cast<std::size_t>((slabs + kSlabsPerTask - 1) / kSlabsPerTask);
    parallelFor(0, tasks, [&](std::size_t t) {
      thread_local std::vector<double> table;  // grows to the largest particle once per thread
      const int k0 = static_cast<int>(t) * kSlabsPerTask;
      addToSlabs<D>(particles, kernel, dt, a, k0, std::min(slabs, k0 + kSlabsPerTask), faces, solid, placement, table);
    }, 1);
  }
}

template <int D>
Vec<D> vortexForceAt(const VortexParticles<D>& particles, VortexKernel kernel, const Vec<D>& position) {
  Vec<D> force = Vec<D>::Zero();
  const auto& x = particles.positions();
  for (std::size_t p = 0; p < x.size(); ++p)
    force += vortexParticleForce<D>(kernel, Vec<D>(position - x[p].template cast<double>()),
                                    particles.vorticities()[p], particles.radii()[p], particles.strengths()[p]);
  return force;
}

template void addVortexForce<2>(const VortexParticles<2>&, VortexKernel, double, MacGrid<2>&, const Grid<float, 2>*,
                                const BlockPlacement<2>&);
template void addVortexForce<3>(const VortexParticles<3>&, VortexKernel, double, MacGrid<3>&, const Grid<float, 3>*,
                                const BlockPlacement<3>&);
template Vec<2> vortexForceAt<2>(const VortexParticles<2>&, VortexKernel, const Vec<2>&);
template Vec<3> vortexForceAt<3>(const VortexParticles<3>&, VortexKernel, const Vec<3>&);

}  // namespace msim::fluid
