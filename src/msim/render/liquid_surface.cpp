#include "msim/render/liquid_surface.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace msim::render {

namespace {

// Signed distance to the box [lo, hi], negative inside (exact inside and outside).
double boxDistance(const Vec3& x, const Vec3& lo, const Vec3& hi) {
  const Vec3 q = (lo - x).cwiseMax(x - hi);  // per axis: > 0 outside that slab
  const double outside = q.cwiseMax(0.0).norm();
  return outside > 0.0 ? outside : q.maxCoeff();
}

}  // namespace

LiquidSurface::LiquidSurface(const Grid<float, 3>& phi, double stepCells)
    : phi_(&phi), sampler_(phi), lo_(phi.spec().origin), hi_(phi.spec().upper()), dx_(phi.spec().dx) {
  if (phi.count() == 0) throw std::invalid_argument("liquid surface: the level set grid is empty");
  if (phi.offset() != Vec3::Constant(0.5) || phi.size() != phi.spec().res)
    throw std::invalid_argument("liquid surface: the level set grid must be cell-centred");
  if (!std::isfinite(stepCells) || !(stepCells > 0.0))
    throw std::invalid_argument("liquid surface: stepCells must be positive, got " + std::to_string(stepCells));
  step_ = stepCells * dx_;
}

double LiquidSurface::phi(const Vec3& x) const {
  const double box = boxDistance(x, lo_, hi_);
  if (box > 0.0) return box;  // no liquid outside the grid's box
  return std::max(static_cast<double>(sampler_.at(x)(phi_->data().data())), box);
}

Vec3 LiquidSurface::normal(const Vec3& x) const {
  Vec3 g;
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = 0.5 * dx_ * Vec3::Unit(a);
    g[a] = phi(x + e) - phi(x - e);
  }
  return g.norm() > 0.0 ? Vec3(g.normalized()) : Vec3::UnitY();
}

bool LiquidSurface::intersect(const Ray& ray, double tMin, double tMax, bool fromInside, double& tHit) const {
  // f > 0 on the ray's own side, so the search is the same from either side.
  const double sign = fromInside ? -1.0 : 1.0;
  const auto f = [&](double t) { return sign * phi(ray.origin + t * ray.direction); };
  // Only the box holds liquid: search from where the ray enters it to a cell past where it leaves
  // (a ray inside the liquid crosses phi_box = 0 on the face itself).
  double t0, t1;
  if (!intersectBox(ray, lo_, hi_, t0, t1)) return false;
  tMax = std::min(tMax, t1 + dx_);
  double ta = fromInside ? tMin : std::max(tMin, t0 - dx_), fa = f(ta);
  while (!(fa > 0.0)) {  // started on the other side: find the ray's own side first
    ta += 0.25 * step_;
    if (ta >= tMax) return false;
    fa = f(ta);
  }
  while (ta < tMax) {
    const double tb = std::min(ta + std::max(fa, step_), tMax), fb = f(tb);
    if (fb <= 0.0) {
      double lo = ta, hi = tb, flo = fa, fhi = fb;
      for (int k = 0; k < 12; ++k) {
        const double tm = 0.5 * (lo + hi), fm = f(tm);
        (fm > 0.0 ? lo : hi) = tm;
        (fm > 0.0 ? flo : fhi) = fm;
      }
      tHit = flo - fhi > 0.0 ? lo + (hi - lo) * flo / (flo - fhi) : hi;
      return true;
    }
    ta = tb;
    fa = fb;
  }
  return false;
}

}  // namespace msim::render
