#include "msim/crowd/stress/crowd_pressure.hpp"

#include <stdexcept>
#include <vector>

namespace msim::crowd::stress {

void spatialPressure(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, int window,
                     Grid<float, 2>& pressure) {
  if (positions.size() != velocities.size()) throw std::invalid_argument("crowd pressure: positions and velocities differ in number");
  if (window < 0) throw std::invalid_argument("crowd pressure: the window must be >= 0 cells");
  const GridSpec<2>& spec = pressure.spec();
  const int nx = spec.res.x(), ny = spec.res.y();
  // Per cell: the agents' count, velocity sum and squared-speed sum.
  std::vector<double> count(spec.cellCount(), 0.0), sx(spec.cellCount(), 0.0), sy(spec.cellCount(), 0.0),
      s2(spec.cellCount(), 0.0);
  for (std::size_t k = 0; k < positions.size(); ++k) {
    const std::size_t c = spec.clampedCellIndex(positions[k]);
    count[c] += 1.0;
    sx[c] += velocities[k].x();
    sy[c] += velocities[k].y();
    s2[c] += velocities[k].squaredNorm();
  }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      double n = 0.0, vx = 0.0, vy = 0.0, v2 = 0.0;
      int cells = 0;
      for (int dj = -window; dj <= window; ++dj)
        for (int di = -window; di <= window; ++di) {
          const int a = i + di, b = j + dj;
          if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
          const std::size_t c = static_cast<std::size_t>(a + nx * b);
          n += count[c];
          vx += sx[c];
          vy += sy[c];
          v2 += s2[c];
          ++cells;
        }
      float p = 0.0f;
      if (n >= 2.0) {
        const double variance = std::max(0.0, v2 / n - (vx * vx + vy * vy) / (n * n));
        p = static_cast<float>(n / (cells * spec.dx * spec.dx) * variance);
      }
      pressure(IVec<2>(i, j)) = p;
    }
}

}  // namespace msim::crowd::stress
