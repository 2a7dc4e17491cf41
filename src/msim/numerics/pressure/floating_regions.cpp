#include "msim/numerics/pressure/floating_regions.hpp"

#include "msim/core/parallel.hpp"

namespace msim::numerics {

template <int D>
FloatingRegions<D>::FloatingRegions(const MacGrid<D>& faceWeight, const std::vector<float>& dirichletDiagonal) {
  const GridSpec<D>& spec = faceWeight.spec();
  const Grid<float, D> cells(spec);  // only for its index arithmetic
  std::vector<std::uint8_t> visited(spec.cellCount(), 0);
  // Floating region of every cell (kNone: grounded, or inside the solid). The cell lists are built
  // from it in index order afterwards: removeMeans then walks memory forwards, where the
  // depth-first visiting order made every access a cache miss.
  constexpr std::uint32_t kNone = ~std::uint32_t{0};
  std::vector<std::uint32_t> label(spec.cellCount(), kNone);
  std::vector<std::uint32_t> stack, region;
  std::uint32_t floating = 0;
  // Flood fill one region at a time (done once per change of the solids, not per solve).
  for (std::size_t seed = 0; seed < visited.size(); ++seed) {
    if (visited[seed]) continue;
    region.clear();
    bool grounded = false;
    visited[seed] = 1;
    stack.push_back(static_cast<std::uint32_t>(seed));
    while (!stack.empty()) {
      const std::uint32_t cell = stack.back();
      stack.pop_back();
      const IVec<D> c = cells.coord(cell);
      bool open = false;
      if (!dirichletDiagonal.empty() && dirichletDiagonal[cell] > 0.0f) open = grounded = true;
      for (int a = 0; a < D; ++a) {
        for (int side = 0; side < 2; ++side) {
          IVec<D> face = c;
          face[a] += side;
          if (faceWeight.component(a)(face) <= 0.0f) continue;
          open = true;
          IVec<D> nb = c;
          nb[a] += side ? 1 : -1;
          if (!cells.inside(nb)) {
            grounded = true;
            continue;
          }
          const std::size_t n = cells.index(nb);
          if (!visited[n]) {
            visited[n] = 1;
            stack.push_back(static_cast<std::uint32_t>(n));
          }
        }
      }
      if (open) region.push_back(cell);  // cells with no open face are inside the solid
    }
    if (grounded || region.empty()) continue;
    for (const std::uint32_t cell : region) label[cell] = floating;
    ++floating;
  }
  regions_.resize(floating);
  for (std::size_t cell = 0; cell < label.size(); ++cell)
    if (label[cell] != kNone) regions_[label[cell]].push_back(static_cast<std::uint32_t>(cell));
}

template <int D>
void FloatingRegions<D>::removeMeans(std::vector<float>& v) const {
  for (const auto& region : regions_) {
    const double mean = parallelSum(region.size(), [&](std::size_t k) { return double(v[region[k]]); }) /
                        static_cast<double>(region.size());
    const float m = static_cast<float>(mean);
    parallelFor(0, region.size(), [&](std::size_t k) { v[region[k]] -= m; });
  }
}

template class FloatingRegions<2>;
template class FloatingRegions<3>;

}  // namespace msim::numerics
