#pragma once
// The per-frame picture of a granular scene: an orthographic view along one grid axis (a side view
// by default, outputs.preview.view_axis / up_axis) of the particles, or of the render points when
// there are any, as discs coloured by material and darkened with depth, z-buffered with the
// bodies' flat-shaded triangles, over a backdrop showing how much static solid each column holds.
// Deliberately simple and O(points + body triangles + pixels).
#include <memory>
#include <vector>

#include "msim/geometry/shape.hpp"
#include "msim/granular/granular_simulation.hpp"
#include "msim/io/png.hpp"
#include "msim/render/density_preview.hpp"

namespace msim::scene {

class GranularPreview {
 public:
  GranularPreview(const GridSpec<3>& grid, const render::PreviewSettings& settings,
                  const std::vector<std::shared_ptr<const geometry::Shape<3>>>& solids);

  // `colours`: linear RGB per material; `bodies`: world indices of the bodies to draw.
  io::Image render(const granular::GranularSimulation& sim, const std::vector<Vec3>& colours,
                   const std::vector<int>& bodies) const;

 private:
  // Pixel coordinates (x right, y down) and depth (larger = nearer) of a world point.
  Vec3 project(const Vec3& x) const;

  GridSpec<3> grid_;
  int view_ = 2, up_ = 1, right_ = 0;
  double rightSign_ = 1.0;  // +1 when the image's right is +right_ axis
  int pixelsPerCell_ = 1, width_ = 1, height_ = 1;
  std::vector<float> solidColumns_;  // per cell column (right, up): solid fraction along the view
};

}  // namespace msim::scene
