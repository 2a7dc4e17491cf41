#pragma once
// Volume (area in 2D) enclosed by a level set, phi < 0 inside, with the smeared Heaviside of
// Enright et al. (2002): H(phi) = 1 for phi < -eps, 0 for phi > eps, and
// 1/2 - phi / (2 eps) - sin(pi phi / eps) / (2 pi) in between, eps = 1.5 dx. Cells with a solid
// mask > 0.5 (when given) are left out: the liquid cannot be there; so are the cells outside
// `cells` when given (a split run's own cells).
#include <cmath>
#include <numbers>

#include "msim/core/grid.hpp"
#include "msim/core/index_box.hpp"
#include "msim/core/parallel.hpp"

namespace msim::numerics {

inline double smearedInside(double phi, double eps) {
  if (phi < -eps) return 1.0;
  if (phi > eps) return 0.0;
  return 0.5 - 0.5 * phi / eps - std::sin(std::numbers::pi * phi / eps) / (2.0 * std::numbers::pi);
}

template <int D>
double enclosedVolume(const Grid<float, D>& phi, const Grid<float, D>* solid = nullptr,
                      const IndexBox<D>* cells = nullptr) {
  const double eps = 1.5 * phi.spec().dx;
  return phi.spec().cellVolume() * parallelSum(phi.count(), [&](std::size_t i) {
           if ((solid && (*solid)[i] > 0.5f) || (cells && !cells->contains(phi.coord(i)))) return 0.0;
           return smearedInside(phi[i], eps);
         });
}

}  // namespace msim::numerics
