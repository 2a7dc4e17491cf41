#include "msim/numerics/level_set/extrapolation.hpp"

#include <algorithm>
#include <stdexcept>

namespace msim::numerics {

template <int D>
std::size_t extrapolateAlongNormals(Grid<float, D>& u, std::vector<std::uint8_t>& known, const Grid<float, D>& phi,
                                    double bandCells) {
  if (!u.sameLayout(phi) || known.size() != u.count())
    throw std::invalid_argument("extrapolation: u, known and phi must have one layout");
  const float band = static_cast<float>(bandCells * u.spec().dx);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < u.count(); ++i)
    if (!known[i] && phi[i] <= band) order.push_back(i);
  // Increasing phi; the index breaks ties so the result does not depend on the sort.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return phi[a] < phi[b] || (phi[a] == phi[b] && a < b);
  });
  std::size_t filled = 0;
  for (const std::size_t i : order) {
    const IVec<D> c = u.coord(i);
    double weighted = 0.0, weights = 0.0, plain = 0.0;
    int count = 0;
    for (int a = 0; a < D; ++a) {
      for (int side = -1; side <= 1; side += 2) {
        if (c[a] + side < 0 || c[a] + side >= u.size()[a]) continue;
        const std::size_t j = i + side * u.stride(a);
        if (!known[j]) continue;
        const double w = std::max(0.0f, phi[i] - phi[j]);
        weighted += w * u[j];
        weights += w;
        plain += u[j];
        ++count;
      }
    }
    if (count == 0) continue;  // not reached (yet): an island of the band
    u[i] = static_cast<float>(weights > 0.0 ? weighted / weights : plain / count);
    known[i] = 1;
    ++filled;
  }
  return filled;
}

template std::size_t extrapolateAlongNormals<2>(Grid<float, 2>&, std::vector<std::uint8_t>&, const Grid<float, 2>&,
                                                double);
template std::size_t extrapolateAlongNormals<3>(Grid<float, 3>&, std::vector<std::uint8_t>&, const Grid<float, 3>&,
                                                double);

}  // namespace msim::numerics
