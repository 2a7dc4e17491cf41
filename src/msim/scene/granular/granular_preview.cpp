#include "msim/scene/granular/granular_preview.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "msim/scene/granular/granular_bodies.hpp"

namespace msim::scene {
namespace {

const Vec3 kBackground(0.015, 0.017, 0.022);
const Vec3 kSolid(0.16, 0.16, 0.17);
const Vec3 kBody(0.45, 0.5, 0.62);

}  // namespace

GranularPreview::GranularPreview(const GridSpec<3>& grid, const render::PreviewSettings& settings,
                                 const std::vector<std::shared_ptr<const geometry::Shape<3>>>& solids)
    : grid_(grid), view_(settings.viewAxis), up_(settings.upAxis) {
  right_ = 3 - view_ - up_;
  // The camera looks down -view: right = up x view.
  rightSign_ = Vec3::Unit(up_).cross(Vec3::Unit(view_))[right_];
  pixelsPerCell_ = std::max(2, (settings.minWidth + grid.res[right_] - 1) / grid.res[right_]);
  width_ = grid.res[right_] * pixelsPerCell_;
  height_ = grid.res[up_] * pixelsPerCell_;
  const int columns = grid.res[right_] * grid.res[up_];
  solidColumns_.assign(columns, 0.0f);
  if (solids.empty()) return;
  parallelFor(0, static_cast<std::size_t>(columns), [&](std::size_t c) {
    IVec3 cell;
    cell[right_] = static_cast<int>(c % grid.res[right_]);
    cell[up_] = static_cast<int>(c / grid.res[right_]);
    int inside = 0;
    for (cell[view_] = 0; cell[view_] < grid.res[view_]; ++cell[view_]) {
      const Vec3 x = grid.cellCenter(cell);
      for (const auto& s : solids)
        if (s->distance(x) < 0.0) {
          ++inside;
          break;
        }
    }
    solidColumns_[c] = static_cast<float>(inside) / static_cast<float>(grid.res[view_]);
  });
}

Vec3 GranularPreview::project(const Vec3& x) const {
  const Vec3 s = (x - grid_.origin) / grid_.dx * pixelsPerCell_;
  const double across = rightSign_ > 0 ? s[right_] : width_ - s[right_];
  return Vec3(across, height_ - s[up_], s[view_]);
}

io::Image GranularPreview::render(const granular::GranularSimulation& sim, const std::vector<Vec3>& colours,
                                  const std::vector<int>& bodies) const {
  io::ImageF image(width_, height_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const int cr = rightSign_ > 0 ? x / pixelsPerCell_ : (width_ - 1 - x) / pixelsPerCell_;
      const int cu = (height_ - 1 - y) / pixelsPerCell_;
      const float f = solidColumns_[static_cast<std::size_t>(cu) * grid_.res[right_] + cr];
      const Vec3 c = kBackground + f * (kSolid - kBackground);
      for (int k = 0; k < 3; ++k) image.pixel(x, y)[k] = static_cast<float>(c[k]);
    }
  std::vector<float> depth(static_cast<std::size_t>(width_) * height_, -std::numeric_limits<float>::infinity());
  const double depthRange = grid_.res[view_] * pixelsPerCell_;
  auto put = [&](int x, int y, double z, const Vec3& colour, double shade) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    float& d = depth[static_cast<std::size_t>(y) * width_ + x];
    if (z <= d) return;
    d = static_cast<float>(z);
    for (int k = 0; k < 3; ++k) image.pixel(x, y)[k] = static_cast<float>(shade * colour[k]);
  };

  // Points: the render points when there are any (finer), else the particles.
  const granular::GranularParticles& p = sim.particles();
  const granular::RenderPoints* points = sim.renderPoints();
  const bool fine = points && points->size() > 0;
  const std::size_t n = fine ? points->size() : p.size();
  const double perParticle = fine ? std::max(1.0, double(points->size()) / std::max<std::size_t>(1, p.size())) : 1.0;
  // Packed particles sit a particle spacing h apart (dx/2 at 8 per cell); discs of 0.7 h (shrunk by
  // the render points' count) close the gaps.
  const double spacing = granular::particleSpacing(1.0, sim.settings().particlesPerCell);
  const double radius = std::max(0.7, 0.7 * spacing * pixelsPerCell_ / std::cbrt(perParticle));
  const int reach = static_cast<int>(std::ceil(radius));
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 x = (fine ? points->positions()[i] : p.position[i]).cast<double>();
    const std::size_t parent = fine ? points->parents()[i] : i;
    const std::size_t m = parent < p.size() ? p.material[parent] : 0;
    const Vec3& colour = m < colours.size() ? colours[m] : colours.front();
    const Vec3 q = project(x);
    // Nearer (larger depth) is brighter: the depth cue that makes a side view readable.
    const double shade = 0.3 + 0.7 * std::clamp(q.z() / depthRange, 0.0, 1.0);
    const int cx = static_cast<int>(std::floor(q.x())), cy = static_cast<int>(std::floor(q.y()));
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        const double ox = cx + dx + 0.5 - q.x(), oy = cy + dy + 0.5 - q.y();
        if (ox * ox + oy * oy <= radius * radius) put(cx + dx, cy + dy, q.z(), colour, shade);
      }
  }

  // Bodies: flat-shaded triangles (two-sided), lit from the camera and above.
  const Vec3 light = (Vec3::Unit(view_) + 0.6 * Vec3::Unit(up_)).normalized();
  for (int index : bodies) {
    const TriangleMesh mesh = bodyMesh(sim.world().bodies()[index]);
    for (const auto& t : mesh.triangles) {
      const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
      const Vec3 normal = (b - a).cross(c - a).normalized();
      const double shade = 0.35 + 0.65 * std::abs(normal.dot(light));
      const Vec3 pa = project(a), pb = project(b), pc = project(c);
      const double area = (pb.x() - pa.x()) * (pc.y() - pa.y()) - (pc.x() - pa.x()) * (pb.y() - pa.y());
      if (std::abs(area) < 1e-12) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({pa.x(), pb.x(), pc.x()}))));
      const int x1 = std::min(width_ - 1, static_cast<int>(std::ceil(std::max({pa.x(), pb.x(), pc.x()}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({pa.y(), pb.y(), pc.y()}))));
      const int y1 = std::min(height_ - 1, static_cast<int>(std::ceil(std::max({pa.y(), pb.y(), pc.y()}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const double px = x + 0.5, py = y + 0.5;
          const double wa = ((pb.x() - px) * (pc.y() - py) - (pc.x() - px) * (pb.y() - py)) / area;
          const double wb = ((pc.x() - px) * (pa.y() - py) - (pa.x() - px) * (pc.y() - py)) / area;
          const double wc = 1.0 - wa - wb;
          if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
          put(x, y, wa * pa.z() + wb * pb.z() + wc * pc.z(), kBody, shade);
        }
    }
  }
  return image.toImage8();
}

}  // namespace msim::scene
