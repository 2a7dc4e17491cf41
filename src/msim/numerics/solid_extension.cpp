#include "msim/numerics/solid_extension.hpp"

#include <cstdint>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

template <int D>
SolidExtension<D>::SolidExtension(const Grid<float, D>& solid, int layers) {
  std::vector<std::uint8_t> given(solid.count());
  for (std::size_t i = 0; i < solid.count(); ++i) given[i] = solid[i] <= 0.5f;
  start_.assign(1, 0);
  std::vector<std::size_t> layer;
  for (int k = 0; k < layers; ++k) {
    layer.clear();
    for (std::size_t i = 0; i < solid.count(); ++i) {
      if (given[i]) continue;
      const IVec<D> c = solid.coord(i);
      const std::size_t first = neighbours_.size();
      for (int a = 0; a < D; ++a)
        for (int s : {-1, 1}) {
          IVec<D> nb = c;
          nb[a] += s;
          if (solid.inside(nb) && given[solid.index(nb)]) neighbours_.push_back(solid.index(nb));
        }
      if (neighbours_.size() > first) {
        cells_.push_back(i);
        start_.push_back(neighbours_.size());
        layer.push_back(i);
      }
    }
    // Marked only now: a cell's neighbours come from the layers below its own.
    for (const std::size_t i : layer) given[i] = 1;
    layerEnd_.push_back(cells_.size());
    if (layer.empty()) break;
  }
}

template <int D>
void SolidExtension<D>::extend(Grid<float, D>& field) const {
  std::size_t begin = 0;
  for (const std::size_t end : layerEnd_) {
    parallelFor(begin, end, [&](std::size_t k) {
      double sum = 0.0;
      for (std::size_t j = start_[k]; j < start_[k + 1]; ++j) sum += field[neighbours_[j]];
      field[cells_[k]] = static_cast<float>(sum / static_cast<double>(start_[k + 1] - start_[k]));
    }, 256);
    begin = end;
  }
}

template class SolidExtension<2>;
template class SolidExtension<3>;

}  // namespace msim::numerics
