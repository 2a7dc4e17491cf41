#include "msim/fluid/smoke/buoyancy.hpp"

#include "msim/core/parallel.hpp"

namespace msim::fluid {

template <int D>
void addBuoyancy(MacGrid<D>& velocity, const Grid<float, D>& density, const Grid<float, D>& temperature,
                 const BuoyancyParams& params, double dt, const Grid<float, D>* solid) {
  const int up = params.upAxis;
  auto& v = velocity.component(up);
  const int n = velocity.spec().res[up];
  const double alpha = params.alpha, beta = params.beta, ambient = params.ambientTemperature;
  auto accel = [&](const IVec<D>& c) { return -alpha * density(c) + beta * (temperature(c) - ambient); };
  parallelForCells(v, [&](const IVec<D>& f, std::size_t lin) {
    if (f[up] == 0 || f[up] == n) return;  // walls and open sides are the projection's business
    IVec<D> below = f;
    below[up] -= 1;
    if (solid && ((*solid)(below) > 0.5f || (*solid)(f) > 0.5f)) return;
    v[lin] += static_cast<float>(dt * 0.5 * (accel(below) + accel(f)));
  });
}

template void addBuoyancy<2>(MacGrid<2>&, const Grid<float, 2>&, const Grid<float, 2>&, const BuoyancyParams&, double,
                             const Grid<float, 2>*);
template void addBuoyancy<3>(MacGrid<3>&, const Grid<float, 3>&, const Grid<float, 3>&, const BuoyancyParams&, double,
                             const Grid<float, 3>*);

}  // namespace msim::fluid
