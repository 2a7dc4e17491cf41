#include "msim/numerics/level_set/fast_marching.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <stdexcept>
#include <utility>
#include <vector>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

constexpr float kUnset = std::numeric_limits<float>::infinity();

bool inside(float phi) { return phi < 0.0f; }

// Distance of an interface cell to the plane through its crossings (step 1), or kUnset when no
// neighbour has the other sign.
template <int D>
float interfaceDistance(const Grid<float, D>& phi, const IVec<D>& c, std::size_t i) {
  const float p = phi[i];
  double inverseSquares = 0.0;
  bool crossing = false;
  for (int a = 0; a < D; ++a) {
    double theta = 2.0;  // fraction of the spacing to the nearer crossing on this axis
    for (int side = -1; side <= 1; side += 2) {
      IVec<D> n = c;
      n[a] += side;
      if (n[a] < 0 || n[a] >= phi.size()[a]) continue;
      const float q = phi[i + side * phi.stride(a)];
      if (inside(p) == inside(q)) continue;
      theta = std::min(theta, double(p) / (double(p) - double(q)));
    }
    if (theta > 1.0) continue;
    crossing = true;
    if (theta <= 0.0) return 0.0f;  // the sample lies on the interface
    inverseSquares += 1.0 / (theta * theta);
  }
  if (!crossing) return kUnset;
  return static_cast<float>(phi.spec().dx / std::sqrt(inverseSquares));
}

// First-order upwind solution of |grad d| = 1 at a cell from the smallest accepted neighbour
// value per axis (step 2).
template <int D>
float eikonalUpdate(const std::vector<float>& dist, const std::vector<std::uint8_t>& accepted,
                    const Grid<float, D>& grid, const IVec<D>& c, std::size_t i, double h) {
  std::array<double, 3> a{};  // the smallest accepted neighbour per axis, sorted (D <= 3)
  int m = 0;
  for (int axis = 0; axis < D; ++axis) {
    double best = kUnset;
    for (int side = -1; side <= 1; side += 2) {
      IVec<D> n = c;
      n[axis] += side;
      if (n[axis] < 0 || n[axis] >= grid.size()[axis]) continue;
      const std::size_t j = i + side * grid.stride(axis);
      if (accepted[j]) best = std::min(best, double(dist[j]));
    }
    if (best < kUnset) a[m++] = best;
  }
  for (int k = 1; k < m; ++k)  // insertion sort of at most three values
    for (int j = k; j > 0 && a[j] < a[j - 1]; --j) std::swap(a[j], a[j - 1]);
  double d = a[0] + h;
  if (m >= 2 && d > a[1]) {
    const double diff = a[0] - a[1];
    d = 0.5 * (a[0] + a[1] + std::sqrt(std::max(0.0, 2.0 * h * h - diff * diff)));
    if (m >= 3 && d > a[2]) {
      const double s = a[0] + a[1] + a[2], q = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
      d = (s + std::sqrt(std::max(0.0, s * s - 3.0 * (q - h * h)))) / 3.0;
    }
  }
  return static_cast<float>(d);
}

}  // namespace

template <int D>
FastMarchingStats reinitializeFastMarching(Grid<float, D>& phi, double bandCells) {
  if (!(bandCells > 0.0) || !std::isfinite(bandCells))
    throw std::invalid_argument("fast marching: the band must be a positive number of cells");
  const std::size_t n = phi.count();
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(phi[i])) throw std::invalid_argument("fast marching: phi is not finite");
  const double h = phi.spec().dx;
  const double band = bandCells * h;

  std::vector<float> dist(n, kUnset);
  std::vector<std::uint8_t> accepted(n, 0);
  parallelForCells(phi, [&](const IVec<D>& c, std::size_t i) {
    dist[i] = interfaceDistance(phi, c, i);
    accepted[i] = dist[i] < kUnset;
  });

  FastMarchingStats stats;
  using Entry = std::pair<float, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  auto consider = [&](std::size_t j) {
    const IVec<D> c = phi.coord(j);
    const float d = eikonalUpdate(dist, accepted, phi, c, j, h);
    if (d < dist[j]) {
      dist[j] = d;
      heap.emplace(d, j);
    }
  };
  auto neighbours = [&](std::size_t i, auto&& f) {
    const IVec<D> c = phi.coord(i);
    for (int a = 0; a < D; ++a) {
      if (c[a] > 0) f(i - phi.stride(a));
      if (c[a] + 1 < phi.size()[a]) f(i + phi.stride(a));
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!accepted[i]) continue;
    ++stats.interfaceCells;
    neighbours(i, [&](std::size_t j) {
      if (!accepted[j]) consider(j);
    });
  }
  while (!heap.empty()) {
    const auto [d, i] = heap.top();
    heap.pop();
    if (accepted[i] || d > dist[i]) continue;  // already final, or a stale entry
    if (d > band) break;
    accepted[i] = 1;
    ++stats.marchedCells;
    neighbours(i, [&](std::size_t j) {
      if (!accepted[j]) consider(j);
    });
  }

  const float limit = static_cast<float>(band);
  parallelFor(0, n, [&](std::size_t i) {
    const float d = accepted[i] ? std::min(dist[i], limit) : limit;
    phi[i] = inside(phi[i]) ? -d : d;
  });
  return stats;
}

template FastMarchingStats reinitializeFastMarching<2>(Grid<float, 2>&, double);
template FastMarchingStats reinitializeFastMarching<3>(Grid<float, 3>&, double);

}  // namespace msim::numerics
