#pragma once
// SolidExtension<D>: continues a cell-centred field into the solid cells next to the fluid, layer
// by layer. Layer 0 is the fluid (cells with solid mask <= 0.5); each solid cell of layer k takes
// the mean of its face neighbours in the layers below k. Smoke extends its scalars one layer so
// that back-traces ending in an obstacle read fluid values; a liquid extends its phi three layers
// so that an obstacle's wall meets the surface at 90 degrees instead of being a surface itself.
// The layers and neighbours are found once per mask (CSR lists); extend() only averages.
#include <cstddef>
#include <vector>

#include "msim/core/grid.hpp"

namespace msim::numerics {

template <int D>
class SolidExtension {
 public:
  SolidExtension() = default;
  SolidExtension(const Grid<float, D>& solid, int layers);

  // Overwrites the solid cells of every layer, in layer order, from the field's fluid values.
  void extend(Grid<float, D>& field) const;
  bool empty() const { return cells_.empty(); }

 private:
  std::vector<std::size_t> cells_, start_, neighbours_;  // cells of all layers in order; CSR neighbours
  std::vector<std::size_t> layerEnd_;                     // cells_[layerEnd_[k-1] .. layerEnd_[k]) is layer k+1
};

}  // namespace msim::numerics
