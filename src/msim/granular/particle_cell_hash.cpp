#include "msim/granular/particle_cell_hash.hpp"

#include <cmath>

namespace msim::granular {

void ParticleCellHash::build(std::span<const Vecf<3>> positions, double cellSize) {
  Vecf<3> lo = Vecf<3>::Zero(), hi = Vecf<3>::Zero();
  if (!positions.empty()) lo = hi = positions[0];
  for (const Vecf<3>& x : positions) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  origin_ = lo.cast<double>();
  const Vec3 extent = (hi - lo).cast<double>();
  const double maxCells = std::max(1.0, 0.5 * static_cast<double>(positions.size()));
  side_ = cellSize;
  // Cells per axis for side s is floor(extent / s) + 1; grow s until their product fits.
  auto count = [&](double s) { return ((extent / s).array().floor() + 1.0).prod(); };
  while (count(side_) > maxCells) side_ *= 1.25;
  for (int a = 0; a < 3; ++a) cells_[a] = static_cast<int>(std::floor(extent[a] / side_)) + 1;
  const std::size_t buckets = static_cast<std::size_t>(cells_.cast<std::size_t>().prod());
  sort_.sort(positions.size(), buckets, [&](std::size_t i) { return linear(cellOf(positions[i].cast<double>())); });
}

}  // namespace msim::granular
