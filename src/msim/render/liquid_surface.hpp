#pragma once
// A liquid's surface for ray tracing: the zero set of a level set phi saved at the cell centres
// (negative inside the liquid, a signed distance in metres near the surface; the liquid solver's
// "liquid_phi", a narrow band of a few cells), interpolated trilinearly. The liquid is clipped to
// the grid's box, phi_box(x) = max(phi(x), b(x)) with b the signed distance to the box (negative
// inside): a tank's water that touches a wall the camera looks through shows a flat face there,
// as behind a pane of glass too thin to matter, and outside the box there is no liquid.
#include "msim/core/grid.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/grid_sampler.hpp"

namespace msim::render {

class LiquidSurface {
 public:
  // std::invalid_argument: an empty or not cell-centred grid, or stepCells not positive. The grid
  // must outlive the surface. stepCells: the least step of the root search, in cells.
  explicit LiquidSurface(const Grid<float, 3>& phi, double stepCells = 0.5);

  double phi(const Vec3& x) const;  // phi_box above [m]
  bool inside(const Vec3& x) const { return phi(x) < 0.0; }
  // Outward unit normal at x: the gradient of phi_box by central differences over a cell.
  Vec3 normal(const Vec3& x) const;

  // The first t in (tMin, tMax] where the ray crosses from the side `fromInside` to the other.
  // Sphere tracing: steps of |phi| (no surface is nearer than the distance; the saved band clamps
  // far values to a few cells, which only shortens the steps), at least stepCells cells, then
  // bisection of the step that brackets the sign change to 1/4096 of it and a secant step in the
  // last bracket (exact for a plane). If the start sample is already on the other side (an origin
  // set off a surface by round-off), the search begins where the ray is back on its side.
  // Sheets thinner than a step can be stepped over, as in the renderer's other marches.
  bool intersect(const Ray& ray, double tMin, double tMax, bool fromInside, double& tHit) const;

  double cellSize() const { return dx_; }
  const Vec3& lower() const { return lo_; }
  const Vec3& upper() const { return hi_; }

 private:
  const Grid<float, 3>* phi_;
  Sampler sampler_;
  Vec3 lo_, hi_;
  double dx_, step_;
};

}  // namespace msim::render
