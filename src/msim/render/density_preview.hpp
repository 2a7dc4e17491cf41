#pragma once
// A quick look at a density field: an emission-absorption projection along one grid axis with a
// single directional light from "above" (Beer-Lambert shadowing computed by one sweep), an ambient
// term and a dark background. Solid cells (obstacles), when given, are drawn as opaque matte
// surfaces that also cast shadows into the gas. It is the per-frame preview every scene writes; the physically
// based renderer (Stam ch. 5) is a separate module.
#include <array>

#include "msim/core/grid.hpp"
#include "msim/io/png.hpp"

namespace msim::render {

struct PreviewSettings {
  int viewAxis = 2;           // looking down -viewAxis (3D); ignored in 2D
  int upAxis = 1;             // image up; the light shines down this axis
  double extinction = 10.0;   // sigma_t per unit density [m^2/kg]
  double albedo = 0.9;        // scattered fraction of extinguished light
  std::array<float, 3> colour = {0.92f, 0.93f, 0.95f};  // the medium's tint (linear RGB): smoke's near white
  double ambient = 0.25;      // sky light reaching every voxel, relative to the key light
  int minWidth = 480;         // images are upscaled by an integer factor to at least this width
  double depth2D = 0.0;       // optical depth thickness of a 2D grid [m]; 0 means 8 cells
  double emissionScale = 1.0;          // radiance per metre per unit emitter density at the reference
  double emissionReference = 1500.0;   // temperature [K] whose black body has unit luminance
};

// Fire: cells emit emitter * B(T) (black-body colour, brightness ~ T^4; render/blackbody.hpp),
// seen through the smoke in front of them.
template <int D>
struct PreviewEmission {
  const Grid<float, D>* emitter = nullptr;      // e.g. flame density [kg/m^3]
  const Grid<float, D>* temperature = nullptr;  // [K]
};

// `solid` (optional, same layout as density): cells > 0.5 are opaque obstacles.
template <int D>
io::Image renderDensityPreview(const Grid<float, D>& density, const PreviewSettings& settings,
                               const Grid<float, D>* solid = nullptr, const PreviewEmission<D>& emission = {});

}  // namespace msim::render
