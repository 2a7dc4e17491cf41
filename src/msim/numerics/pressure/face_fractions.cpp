#include "msim/numerics/pressure/face_fractions.hpp"

#include <algorithm>

namespace msim::numerics {

float fractionInside(float phiA, float phiB) {
  if (phiA < 0.0f && phiB < 0.0f) return 1.0f;
  if (phiA < 0.0f) return phiA / (phiA - phiB);
  if (phiB < 0.0f) return phiB / (phiB - phiA);
  return 0.0f;
}

// Batty's case analysis on the number of inside corners: one corner cuts off a triangle, two
// adjacent corners a trapezoid, three leave a triangle outside; two diagonal corners are told
// apart by the sign of the centre value (average of the corners).
float fractionInside(float phiLL, float phiLR, float phiUL, float phiUR) {
  // Corners in cyclic order round the square, so list[k] and list[(k+1)%4] share an edge.
  float list[4] = {phiLL, phiLR, phiUR, phiUL};
  const int inside = (phiLL < 0.0f) + (phiLR < 0.0f) + (phiUL < 0.0f) + (phiUR < 0.0f);
  auto rotate = [&] { std::rotate(list, list + 1, list + 4); };
  switch (inside) {
    case 4: return 1.0f;
    case 3: {
      while (list[0] < 0.0f) rotate();  // the single outside corner first
      const float side0 = 1.0f - fractionInside(list[0], list[3]);
      const float side1 = 1.0f - fractionInside(list[0], list[1]);
      return 1.0f - 0.5f * side0 * side1;
    }
    case 2: {
      while (!(list[0] < 0.0f && (list[1] < 0.0f || list[2] < 0.0f))) rotate();
      if (list[1] < 0.0f) {  // adjacent inside corners: a trapezoid
        const float left = fractionInside(list[0], list[3]);
        const float right = fractionInside(list[1], list[2]);
        return 0.5f * (left + right);
      }
      const float middle = 0.25f * (list[0] + list[1] + list[2] + list[3]);
      if (middle < 0.0f) {  // inside region joins the diagonal: subtract two outside triangles
        const float a = 0.5f * (1.0f - fractionInside(list[0], list[3])) * (1.0f - fractionInside(list[2], list[3]));
        const float b = 0.5f * (1.0f - fractionInside(list[0], list[1])) * (1.0f - fractionInside(list[2], list[1]));
        return 1.0f - a - b;
      }
      const float a = 0.5f * fractionInside(list[0], list[1]) * fractionInside(list[0], list[3]);
      const float b = 0.5f * fractionInside(list[2], list[1]) * fractionInside(list[2], list[3]);
      return a + b;
    }
    case 1: {
      while (!(list[0] < 0.0f)) rotate();
      return 0.5f * fractionInside(list[0], list[3]) * fractionInside(list[0], list[1]);
    }
    default: return 0.0f;
  }
}

template <int D>
MacGrid<D> openFaceFractions(const GridSpec<D>& spec, const Grid<float, D>& nodalSolidPhi) {
  MacGrid<D> open(spec);
  for (int a = 0; a < D; ++a) {
    auto& w = open.component(a);
    const int b = (a + 1) % D;  // the axes spanning a face normal to a
    const int c = (a + 2) % D;
    parallelForCells(w, [&](const IVec<D>& f, std::size_t lin) {
      IVec<D> nb = f;
      nb[b] += 1;
      float inside;
      if constexpr (D == 2) {
        inside = fractionInside(nodalSolidPhi(f), nodalSolidPhi(nb));
      } else {
        IVec<D> nc = f, nbc = nb;
        nc[c] += 1;
        nbc[c] += 1;
        inside = fractionInside(nodalSolidPhi(f), nodalSolidPhi(nb), nodalSolidPhi(nc), nodalSolidPhi(nbc));
      }
      w[lin] = std::clamp(1.0f - inside, 0.0f, 1.0f);
    });
  }
  return open;
}

template MacGrid<2> openFaceFractions<2>(const GridSpec<2>&, const Grid<float, 2>&);
template MacGrid<3> openFaceFractions<3>(const GridSpec<3>&, const Grid<float, 3>&);

}  // namespace msim::numerics
