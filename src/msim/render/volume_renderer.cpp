#include "msim/render/volume_renderer.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "msim/core/parallel.hpp"
#include "msim/core/seconds_since.hpp"
#include "msim/render/blackbody.hpp"
#include "msim/render/grid_sampler.hpp"
#include "msim/render/liquid_tracer.hpp"
#include "msim/render/phase_function.hpp"

namespace msim::render {

namespace {

constexpr double kInv4Pi = 0.25 / std::numbers::pi;
constexpr double kMinTransmittance = 1e-4;  // early ray termination: what is left cannot show in 8 bits
constexpr int kBrick = 8;                   // cells per side of an empty-space-skipping brick
constexpr int kSweepSlices = 8;             // slices a directional light's path is marched between interpolations

bool finiteNonNegative(const Vec3& v) { return v.allFinite() && (v.array() >= 0.0).all(); }

void checkCellCentred(const Grid<float, 3>& g, const char* name) {
  if (g.count() == 0) throw std::invalid_argument(std::string("volume renderer: the ") + name + " grid is empty");
  if (g.offset() != Vec3::Constant(0.5) || g.size() != g.spec().res)
    throw std::invalid_argument(std::string("volume renderer: the ") + name + " grid must be cell-centred");
}

void checkSameLayout(const Grid<float, 3>& density, const Grid<float, 3>* g, const char* name) {
  if (g && !g->sameLayout(density))
    throw std::invalid_argument(std::string("volume renderer: the ") + name +
                                " grid does not have the density grid's layout (spec, size, offset)");
}

// Distance along the unit direction d from x (inside the box) to the box's boundary.
double exitDistance(const Vec3& x, const Vec3& d, const Vec3& lo, const Vec3& hi) {
  double t = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0.0) t = std::min(t, (hi[a] - x[a]) / d[a]);
    if (d[a] < 0.0) t = std::min(t, (lo[a] - x[a]) / d[a]);
  }
  return std::max(t, 0.0);
}

// Interpolation of the optical depth towards a directional light along one lateral axis of a slice
// at sample coordinate s (cell centres at 0..n-1, box faces at -0.5 and n - 0.5): linear between
// centres, and beyond the outer centre linear down to 0 at the face, where the path leaves the box.
// (Clamping instead would hand each border cell the depth of the border cell nearer the light, and
// paths along the sides would never leave the box.) The sweep only looks beyond the face the
// light's path heads for, so the depth there is indeed 0.
struct LateralStencil {
  int index[2];
  double depthWeight[2];
};

LateralStencil lateralStencil(double s, int n) {
  if (s >= 0.0 && s <= n - 1.0 && n >= 2) {
    const int i0 = std::min(static_cast<int>(s), n - 2);
    const double f = s - i0;
    return {{i0, i0 + 1}, {1.0 - f, f}};
  }
  const int edge = s < 0.0 ? 0 : n - 1;
  const double beyond = std::abs(s - edge);  // cells past the outer centre, at most 0.5 here
  return {{edge, edge}, {std::max(1.0 - 2.0 * beyond, 0.0), 0.0}};
}

// Integral of the density along x + t dir for t in [0, length]: midpoint rule with equal steps of
// at most ds.
double densityIntegral(const Sampler& sampler, const float* rho, const Vec3& x, const Vec3& dir, double length,
                       double ds) {
  if (!(length > 0.0)) return 0.0;
  const int steps = std::max(1, static_cast<int>(std::ceil(length / ds)));
  const double h = length / steps;
  double sum = 0.0;
  for (int m = 0; m < steps; ++m) sum += std::max(sampler.at(x + (m + 0.5) * h * dir)(rho), 0.0f);
  return h * sum;
}

// Visibility of the path x + t dir, t in [0, length], past solid obstacles of the signed distance
// `sdf` (see lightTransmittance): clamp(1 + d_min / dx, 0, 1) over samples at the midpoints of steps
// of at most ds. dStart, the distance at x, skips paths that cannot reach a surface (a distance is
// 1-Lipschitz; the cell of margin covers the trilinear interpolation).
double pathVisibility(const Sampler& sampler, const float* sdf, const Vec3& x, const Vec3& dir, double length,
                      double ds, double dx, double dStart) {
  if (!(length > 0.0) || dStart > length + dx) return 1.0;
  const int steps = std::max(1, static_cast<int>(std::ceil(length / ds)));
  const double h = length / steps;
  double least = dStart;
  for (int m = 0; m < steps; ++m) least = std::min(least, static_cast<double>(sampler.at(x + (m + 0.5) * h * dir)(sdf)));
  return std::clamp(1.0 + least / dx, 0.0, 1.0);
}

// densityIntegral over the path from a cell centre along dir for `length` as fixed weights on
// neighbouring cells: the samples sit at the same place relative to every cell centre, so the
// trilinear weights are the same for all cells whose neighbours all exist. Summing ~50 weighted
// cells costs a fraction of the per-sample weight computation. (Negative densities are clamped
// per cell here and per sample in densityIntegral: the two differ only at undershoots a
// simulation may leave.)
class PathStencil {
 public:
  PathStencil(const Grid<float, 3>& rho, const Vec3& dir, double length, double ds) : n_(rho.size()) {
    const int steps = std::max(1, static_cast<int>(std::ceil(length / ds)));
    const double h = length / steps, invDx = 1.0 / rho.spec().dx;
    std::vector<std::pair<IVec3, double>> weights;
    for (int m = 0; m < steps; ++m) {
      const Vec3 o = (m + 0.5) * h * invDx * dir;  // sample offset from the cell centre [cells]
      const IVec3 f(static_cast<int>(std::floor(o[0])), static_cast<int>(std::floor(o[1])),
                    static_cast<int>(std::floor(o[2])));
      const Vec3 t = o - f.cast<double>();
      for (int corner = 0; corner < 8; ++corner) {
        IVec3 delta = f;
        double w = h;
        for (int a = 0; a < 3; ++a) {
          const bool upper = (corner >> a) & 1;
          delta[a] += upper;
          w *= upper ? t[a] : 1.0 - t[a];
        }
        if (w == 0.0) continue;
        const auto same = std::find_if(weights.begin(), weights.end(), [&](const auto& e) { return e.first == delta; });
        if (same != weights.end())
          same->second += w;
        else
          weights.emplace_back(delta, w);
      }
    }
    lo_ = hi_ = weights.front().first;
    for (const auto& [delta, w] : weights) {
      lo_ = lo_.cwiseMin(delta);
      hi_ = hi_.cwiseMax(delta);
      entries_.push_back({delta[0] * rho.stride(0) + delta[1] * rho.stride(1) + delta[2] * rho.stride(2), w});
    }
  }

  bool fits(const IVec3& cell) const {
    return (cell + lo_).minCoeff() >= 0 && ((cell + hi_).array() < n_.array()).all();
  }
  double operator()(const float* rho, std::size_t i) const {
    double sum = 0.0;
    for (const Entry& e : entries_) sum += e.weight * std::max(rho[static_cast<std::ptrdiff_t>(i) + e.offset], 0.0f);
    return sum;
  }

 private:
  struct Entry {
    std::ptrdiff_t offset;
    double weight;
  };
  IVec3 n_, lo_, hi_;
  std::vector<Entry> entries_;
};

// The grids a light sweep fills: optical depth per cell and, with solids, the path's visibility.
class SweepGrids {
 public:
  SweepGrids(const Grid<float, 3>& rho, const Grid<float, 3>* sdf) : depth_(rho.spec(), rho.size(), rho.offset()) {
    if (sdf) visibility_.emplace(rho.spec(), rho.size(), rho.offset());
  }
  float* depth() { return depth_.data().data(); }
  float* vis() { return visibility_ ? visibility_->data().data() : nullptr; }
  // T = exp(-depth) V, in place of the depth.
  Grid<float, 3> transmittance() {
    float* d = depth();
    const float* v = vis();
    parallelFor(0, depth_.count(), [&](std::size_t i) { d[i] = std::exp(-d[i]) * (v ? v[i] : 1.0f); });
    return std::move(depth_);
  }

 private:
  Grid<float, 3> depth_;
  std::optional<Grid<float, 3>> visibility_;
};

// The optical depth and visibility carried from slice `slice` of axis a: bilinear in the cells
// (b, c) of sb and sc there. Weights that fall off beyond the box faces see depth 0 and V = 1.
struct CarriedPath {
  double depth = 0.0, visibility = 1.0;
};
CarriedPath carriedFromSlice(const Grid<float, 3>& rho, const float* depth, const float* vis, int a, int slice,
                             const LateralStencil& sb, const LateralStencil& sc) {
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  IVec3 p;
  p[a] = slice;
  CarriedPath carried;
  for (int u = 0; u < 2; ++u)
    for (int v = 0; v < 2; ++v) {
      p[b] = sb.index[u];
      p[c] = sc.index[v];
      const double w = sb.depthWeight[u] * sc.depthWeight[v];
      carried.depth += w * depth[rho.index(p)];
      if (vis) carried.visibility -= w * (1.0 - vis[rho.index(p)]);
    }
  return carried;
}

// Optical depth from every cell centre towards a directional light (see lightTransmittance),
// returned as transmittance. Slices across the axis closest to the light are done in order from
// the light's side; each cell marches its path exactly over kSweepSlices slices and adds the depth
// interpolated where the path crosses that earlier slice. The crossing is at the same offset from
// every cell, so the stencil is fixed. Interpolating at every slice would be cheapest, but each
// interpolation smears the depth like upwind advection does, and shadow edges (a box edge's
// included) would blur by sqrt(slices) cells; marching kSweepSlices slices per interpolation cuts
// that by sqrt(kSweepSlices) at kSweepSlices / stepCells samples per cell, which PathStencil makes
// cheap away from the borders.
// With solids (sdf), each cell's visibility is carried the same way, interpolated as a visibility:
// beyond the box faces, where lateralStencil's weights fall off, the missing weight sees V = 1.
Grid<float, 3> sweepDirectional(const Grid<float, 3>& rho, const Grid<float, 3>* sdf, const Vec3& toLight,
                                double sigmaT, double stepCells) {
  SweepGrids grids(rho, sdf);
  float* vis = grids.vis();
  const float* dist = sdf ? sdf->data().data() : nullptr;
  const IVec3 n = rho.size();
  const double dx = rho.spec().dx, ds = stepCells * dx;
  const Vec3 lo = rho.spec().origin, hi = rho.spec().upper();
  int a = 0;
  for (int q = 1; q < 3; ++q)
    if (std::abs(toLight[q]) > std::abs(toLight[a])) a = q;
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  const double la = std::abs(toLight[a]);
  const int towardsLight = toLight[a] > 0.0 ? 1 : -1;
  const int jump = std::min(kSweepSlices, n[a]);
  const double tJump = jump * dx / la;  // path length to the slice `jump` slices closer to the light
  const double shiftB = jump * toLight[b] / la, shiftC = jump * toLight[c] / la;  // its lateral offset [cells]
  const Sampler sampler(rho);
  const PathStencil path(rho, toLight, tJump, ds);
  const float* r = rho.data().data();
  float* d = grids.depth();

  // Cells `jump` or fewer slices apart do not depend on each other: one parallel loop per block.
  for (int first = 0; first < n[a]; first += jump) {
    const int slices = std::min(jump, n[a] - first);
    parallelFor(0, static_cast<std::size_t>(slices) * n[c], [&](std::size_t row) {
      const int step = first + static_cast<int>(row / n[c]);
      IVec3 cell;
      cell[a] = towardsLight > 0 ? n[a] - 1 - step : step;
      cell[c] = static_cast<int>(row % n[c]);
      for (int ib = 0; ib < n[b]; ++ib) {
        cell[b] = ib;
        const Vec3 x = rho.position(cell);
        const double tExit = exitDistance(x, toLight, lo, hi);
        const std::size_t i = rho.index(cell);
        double tau;
        if (tExit <= tJump * (1.0 + 1e-9)) {
          tau = sigmaT * densityIntegral(sampler, r, x, toLight, tExit, ds);  // leaves the box first
          if (vis) vis[i] = static_cast<float>(pathVisibility(sampler, dist, x, toLight, tExit, ds, dx, dist[i]));
        } else {
          const CarriedPath there = carriedFromSlice(rho, d, vis, a, cell[a] + jump * towardsLight,
                                                     lateralStencil(ib + shiftB, n[b]),
                                                     lateralStencil(cell[c] + shiftC, n[c]));
          const double segment =
              path.fits(cell) ? path(r, i) : densityIntegral(sampler, r, x, toLight, tJump, ds);
          tau = there.depth + sigmaT * segment;
          if (vis)
            vis[i] = there.visibility > 0.0 ? static_cast<float>(there.visibility * pathVisibility(sampler, dist, x, toLight,
                                                                                                  tJump, ds, dx, dist[i]))
                                            : 0.0f;
        }
        d[i] = static_cast<float>(tau);
      }
    }, 1);
  }
  return grids.transmittance();
}

// Optical depth from every cell centre to a point or spot light (see lightTransmittance), returned
// as transmittance. As sweepDirectional, but the direction varies per cell: a cell marches its
// path towards the light over kSweepSlices slices across its dominant axis (the axis along which
// the light is farthest) and adds the depth interpolated bilinearly in that slice. The cells used
// there are more than kSweepSlices - 1 cells closer to the light in the max norm (the lateral
// offset shrinks along the path, the stencil adds less than a cell), so cells are done in layers
// of kSweepSlices - 1 of that distance, outward from the light, each layer in parallel. Paths
// that reach the light or leave the box within kSweepSlices slices are marched whole.
Grid<float, 3> sweepPointLight(const Grid<float, 3>& rho, const Grid<float, 3>* sdf, const Vec3& light, double sigmaT,
                               double stepCells) {
  SweepGrids grids(rho, sdf);
  float* vis = grids.vis();
  const float* dist = sdf ? sdf->data().data() : nullptr;
  const IVec3 n = rho.size();
  const double dx = rho.spec().dx, ds = stepCells * dx;
  const Vec3 lo = rho.spec().origin, hi = rho.spec().upper();
  const Vec3 lightIndex = (light - lo) / dx - Vec3::Constant(0.5);  // the light in cell-centre coordinates
  const Sampler sampler(rho);
  const float* r = rho.data().data();
  float* d = grids.depth();

  // Cells in layers of max-norm distance to the light, counted from the nearest cell's (a light far
  // outside the box leaves no empty layers), by a counting sort.
  constexpr int kLayer = kSweepSlices - 1;
  const auto chebyshev = [&](const IVec3& cell) { return (cell.cast<double>() - lightIndex).cwiseAbs().maxCoeff(); };
  const IVec3 nearest = lightIndex.array().round().cast<int>().cwiseMax(0).cwiseMin(n.array() - 1);
  const double nearestDistance = chebyshev(nearest);
  std::vector<std::uint32_t> layerOf(rho.count());
  parallelForCells(rho, [&](const IVec3& cell, std::size_t i) {
    layerOf[i] = static_cast<std::uint32_t>(std::max(chebyshev(cell) - nearestDistance, 0.0) / kLayer);
  });
  const std::uint32_t layers = *std::max_element(layerOf.begin(), layerOf.end()) + 1;
  std::vector<std::size_t> layerStart(layers + 1, 0);
  for (std::uint32_t l : layerOf) ++layerStart[l + 1];
  for (std::uint32_t l = 0; l < layers; ++l) layerStart[l + 1] += layerStart[l];
  std::vector<std::size_t> order(rho.count());
  {
    std::vector<std::size_t> next(layerStart.begin(), layerStart.end() - 1);
    for (std::size_t i = 0; i < rho.count(); ++i) order[next[layerOf[i]]++] = i;
  }

  for (std::uint32_t l = 0; l < layers; ++l) {
    parallelFor(layerStart[l], layerStart[l + 1], [&](std::size_t k) {
      const std::size_t i = order[k];
      const IVec3 cell = rho.coord(i);
      const Vec3 x = rho.position(cell);
      const Vec3 toLight = light - x;
      const double distance = toLight.norm();
      if (!(distance > 0.0)) {
        d[i] = 0.0f;
        if (vis) vis[i] = 1.0f;
        return;
      }
      const Vec3 dir = toLight / distance;
      const double length = std::min(distance, exitDistance(x, dir, lo, hi));  // no medium outside the box
      int a = 0;
      for (int q = 1; q < 3; ++q)
        if (std::abs(dir[q]) > std::abs(dir[a])) a = q;
      const double tJump = kSweepSlices * dx / std::abs(dir[a]);  // path length to the slice kSweepSlices closer
      if (length <= tJump * (1.0 + 1e-9)) {
        d[i] = static_cast<float>(sigmaT * densityIntegral(sampler, r, x, dir, length, ds));
        if (vis) vis[i] = static_cast<float>(pathVisibility(sampler, dist, x, dir, length, ds, dx, dist[i]));
        return;
      }
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      const Vec3 end = (x + tJump * dir - lo) / dx - Vec3::Constant(0.5);  // in cell-centre coordinates
      const CarriedPath there = carriedFromSlice(rho, d, vis, a, cell[a] + (dir[a] > 0.0 ? kSweepSlices : -kSweepSlices),
                                                 lateralStencil(end[b], n[b]), lateralStencil(end[c], n[c]));
      d[i] = static_cast<float>(there.depth + sigmaT * densityIntegral(sampler, r, x, dir, tJump, ds));
      if (vis)
        vis[i] = there.visibility > 0.0
                     ? static_cast<float>(there.visibility * pathVisibility(sampler, dist, x, dir, tJump, ds, dx, dist[i]))
                     : 0.0f;
    }, 256);
  }
  return grids.transmittance();
}

void checkLights(const std::vector<Light>& lights) {
  for (std::size_t l = 0; l < lights.size(); ++l) {
    try {
      lights[l].validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("volume renderer: light " + std::to_string(l) + ": " + e.what());
    }
  }
}

// Bricks of kBrick^3 cells that hold any density or emitter, dilated by one cell so that every
// trilinear sample of a point inside a brick whose 8 corners are not all empty finds it occupied.
class Occupancy {
 public:
  Occupancy(const Grid<float, 3>& rho, const Grid<float, 3>* emitter) : n_(rho.size()) {
    for (int a = 0; a < 3; ++a) bricks_[a] = (n_[a] + kBrick - 1) / kBrick;
    origin_ = rho.spec().origin;
    brickSize_ = kBrick * rho.spec().dx;
    occupied_.assign(static_cast<std::size_t>(bricks_[0]) * bricks_[1] * bricks_[2], 0);
    parallelForCells<3>(bricks_, [&](const IVec3& brick, std::size_t bi) {
      IVec3 from, to;
      for (int a = 0; a < 3; ++a) {
        from[a] = std::max(brick[a] * kBrick - 1, 0);
        to[a] = std::min((brick[a] + 1) * kBrick + 1, n_[a]);
      }
      IVec3 c;
      for (c[2] = from[2]; c[2] < to[2]; ++c[2])
        for (c[1] = from[1]; c[1] < to[1]; ++c[1])
          for (c[0] = from[0]; c[0] < to[0]; ++c[0]) {
            const std::size_t i = rho.index(c);
            if (rho[i] != 0.0f || (emitter && (*emitter)[i] > 0.0f)) {
              occupied_[bi] = 1;
              return;
            }
          }
    });
  }

  // If x lies in an empty brick, the ray parameter where the ray leaves it; otherwise nothing.
  bool emptyExit(const Vec3& x, const Vec3& dir, double tx, double& tExit) const {
    IVec3 b;
    for (int a = 0; a < 3; ++a)
      b[a] = std::clamp(static_cast<int>(std::floor((x[a] - origin_[a]) / brickSize_)), 0, bricks_[a] - 1);
    if (occupied_[(static_cast<std::size_t>(b[2]) * bricks_[1] + b[1]) * bricks_[0] + b[0]]) return false;
    const Vec3 lo = origin_ + b.cast<double>() * brickSize_;
    tExit = tx + exitDistance(x, dir, lo, lo + Vec3::Constant(brickSize_));
    return true;
  }

 private:
  IVec3 n_, bricks_;
  Vec3 origin_;
  double brickSize_;
  std::vector<unsigned char> occupied_;
};

// First zero crossing of the signed distance along the ray within [t0, t1]: steps of the distance
// itself where it exceeds the march step ds (sphere tracing: no surface is nearer than the
// distance), of ds otherwise, then bisection of the step that brackets the crossing and a linear
// interpolation in the last bracket. Solids thinner than about ds can be stepped over, as the
// medium's features thinner than a step are.
bool traceDistance(const Sampler& sampler, const float* sdf, const Ray& ray, double t0, double t1, double ds,
                   double& tHit) {
  const auto at = [&](double t) { return static_cast<double>(sampler.at(ray.origin + t * ray.direction)(sdf)); };
  double ta = t0, da = at(t0);
  if (da <= 0.0) {
    tHit = t0;
    return true;
  }
  while (ta < t1) {
    const double tb = std::min(ta + std::max(da, ds), t1), db = at(tb);
    if (db <= 0.0) {
      double lo = ta, hi = tb, dlo = da, dhi = db;
      for (int k = 0; k < 10; ++k) {  // ds / 1024: a thousandth of a cell at the default step
        const double tm = 0.5 * (lo + hi), dm = at(tm);
        (dm > 0.0 ? lo : hi) = tm;
        (dm > 0.0 ? dlo : dhi) = dm;
      }
      tHit = lo + (hi - lo) * dlo / (dlo - dhi);
      return true;
    }
    ta = tb;
    da = db;
  }
  return false;
}

// Outward unit normal of the box face through which the ray enters it (the slab entered last).
Vec3 entryFaceNormal(const Ray& r, const Vec3& lo, const Vec3& hi) {
  int face = 0;
  double latest = -std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (r.direction[a] == 0.0) continue;
    const double t = ((r.direction[a] > 0.0 ? lo[a] : hi[a]) - r.origin[a]) / r.direction[a];
    if (t > latest) {
      latest = t;
      face = a;
    }
  }
  Vec3 n = Vec3::Zero();
  n[face] = r.direction[face] > 0.0 ? -1.0 : 1.0;
  return n;
}

}  // namespace

void Medium::validate() const {
  if (!std::isfinite(extinction) || extinction < 0.0)
    throw std::invalid_argument("medium: extinction must be finite and >= 0, got " + std::to_string(extinction));
  if (!(albedo >= 0.0 && albedo <= 1.0))
    throw std::invalid_argument("medium: albedo must be in [0, 1], got " + std::to_string(albedo));
  if (!(phaseG > -1.0 && phaseG < 1.0))
    throw std::invalid_argument("medium: phaseG must be in (-1, 1), got " + std::to_string(phaseG));
  if (!std::isfinite(emissionScale) || emissionScale < 0.0)
    throw std::invalid_argument("medium: emissionScale must be finite and >= 0, got " + std::to_string(emissionScale));
  if (!std::isfinite(emissionReference) || !(emissionReference > 0.0))
    throw std::invalid_argument("medium: emissionReference must be a positive temperature, got " +
                                std::to_string(emissionReference));
}

void VolumeRenderSettings::validate() const {
  if (!std::isfinite(stepCells) || !(stepCells > 0.0))
    throw std::invalid_argument("volume render settings: stepCells must be positive, got " + std::to_string(stepCells));
  if (!std::isfinite(exposure) || !(exposure > 0.0))
    throw std::invalid_argument("volume render settings: exposure must be positive, got " + std::to_string(exposure));
  if (!std::isfinite(gamma) || !(gamma > 0.0))
    throw std::invalid_argument("volume render settings: gamma must be positive, got " + std::to_string(gamma));
  if (!finiteNonNegative(background))
    throw std::invalid_argument("volume render settings: background must be finite and non-negative");
  if (!finiteNonNegative(ambient))
    throw std::invalid_argument("volume render settings: ambient must be finite and non-negative");
  if (!finiteNonNegative(surfaceAlbedo) || (surfaceAlbedo.array() > 1.0).any())
    throw std::invalid_argument("volume render settings: surfaceAlbedo must be in [0, 1]");
  if (!finiteNonNegative(meshAlbedo) || (meshAlbedo.array() > 1.0).any())
    throw std::invalid_argument("volume render settings: meshAlbedo must be in [0, 1]");
  sky.validate();
  floor.validate();
  liquid.validate();
}

void VolumeInput::validate() const {
  if (!density) throw std::invalid_argument("volume renderer: the density grid is required (got null)");
  checkCellCentred(*density, "density");
  checkSameLayout(*density, temperature, "temperature");
  checkSameLayout(*density, emitter, "emitter");
  checkSameLayout(*density, fluence, "fluence");
  if (transmittances)
    for (const auto& t : *transmittances) checkSameLayout(*density, &t, "transmittance");
  if (emitter && !temperature)
    throw std::invalid_argument("volume renderer: an emitter grid needs a temperature grid for its colour");
  checkSameLayout(*density, surfaceDistance, "surface distance");
  checkSameLayout(*density, liquid, "liquid level set");
}

double signedDistanceAt(const Grid<float, 3>& distance, const Vec3& x) {
  checkCellCentred(distance, "surface distance");
  const Vec3 lo = distance.spec().origin, hi = distance.spec().upper();
  if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any() || !x.allFinite())
    return std::numeric_limits<double>::infinity();
  return Sampler(distance).at(x)(distance.data().data());
}

void checkCameraOutsideSolids(const Vec3& position, const Grid<float, 3>* surfaceDistance,
                              const std::vector<const TriangleMesh*>& meshes) {
  if (surfaceDistance) {
    const double d = signedDistanceAt(*surfaceDistance, position);
    if (d < 0.0)
      throw std::invalid_argument(
          fmt::format("camera is inside an obstacle (signed distance {:.2g} m at the camera position)", d));
  }
  int crossings = 0;
  const int mesh = meshContaining(meshes, position, &crossings);
  if (mesh >= 0)
    throw std::invalid_argument(
        fmt::format("camera is inside mesh {} (a ray from the camera crosses it {} times)", mesh, crossings));
}

Grid<float, 3> lightTransmittance(const Grid<float, 3>& density, const Light& light, const Medium& medium,
                                  double stepCells, const Grid<float, 3>* surfaceDistance) {
  checkCellCentred(density, "density");
  checkSameLayout(density, surfaceDistance, "surface distance");
  light.validate();
  medium.validate();
  if (!std::isfinite(stepCells) || !(stepCells > 0.0))
    throw std::invalid_argument("lightTransmittance: stepCells must be positive, got " + std::to_string(stepCells));
  if (light.type == Light::Type::Directional)
    return sweepDirectional(density, surfaceDistance, -light.direction.normalized(), medium.extinction, stepCells);
  return sweepPointLight(density, surfaceDistance, light.position, medium.extinction, stepCells);
}

Grid<float, 3> firstScatterSource(const Grid<float, 3>& density, const std::vector<Light>& lights,
                                  const Medium& medium, const std::vector<Grid<float, 3>>& transmittances) {
  checkCellCentred(density, "density");
  medium.validate();
  checkLights(lights);
  if (transmittances.size() != lights.size())
    throw std::invalid_argument("firstScatterSource: " + std::to_string(transmittances.size()) +
                                " transmittance grids for " + std::to_string(lights.size()) + " lights");
  for (const auto& t : transmittances) checkSameLayout(density, &t, "transmittance");
  Grid<float, 3> out(density.spec(), density.size(), density.offset());
  const double sigmaS = medium.albedo * medium.extinction;
  const double minDistance = 0.5 * density.spec().dx;
  parallelForCells(density, [&](const IVec3& cell, std::size_t i) {
    const double rho = std::max(density[i], 0.0f);
    if (!(rho > 0.0)) return;
    const Vec3 x = density.position(cell);
    double e = 0.0;
    for (std::size_t l = 0; l < lights.size(); ++l)
      e += luminance(illuminate(lights[l], x, minDistance).irradiance) * transmittances[l][i];
    out[i] = static_cast<float>(sigmaS * rho * e);
  });
  return out;
}

namespace {

// One frame as the camera's rays see it (see the header): the medium's march, the opaque surfaces
// and their shading, the sky. Camera rays ask it directly, or through the liquid tracer along their
// reflected and refracted rays.
class VolumeScene final : public TracedScene {
 public:
  VolumeScene(const VolumeInput& input, const std::vector<Light>& lights, const Medium& medium,
              const VolumeRenderSettings& settings, const std::vector<Grid<float, 3>>& transmittance,
              const SurfaceScene& surfaces, const LiquidTracer* liquid)
      : lights_(lights),
        medium_(medium),
        settings_(settings),
        surfaces_(surfaces),
        liquid_(liquid),
        occupancy_(*input.density, input.emitter),
        sampler_(*input.density),
        lo_(input.density->spec().origin),
        hi_(input.density->spec().upper()),
        dx_(input.density->spec().dx),
        ds_(settings.stepCells * dx_),
        phase_(medium.phaseG) {
    rho_ = input.density->data().data();
    temperature_ = input.temperature ? input.temperature->data().data() : nullptr;
    emitter_ = input.emitter ? input.emitter->data().data() : nullptr;
    fluence_ = input.fluence ? input.fluence->data().data() : nullptr;
    distance_ = input.surfaceDistance ? input.surfaceDistance->data().data() : nullptr;
    if (temperature_) blackbody_.emplace(medium.emissionReference);
    // Emitter form: emissionScale * emitter * B; Stam's form: sigma_t rho (1 - Omega) emissionScale B.
    emissionWeight_ = emitter_ ? medium.emissionScale : medium.extinction * (1.0 - medium.albedo) * medium.emissionScale;
    // Chromaticity given to the (luminance) fluence: the lights' summed colour at unit luminance.
    Vec3 sum = Vec3::Zero();
    for (const Light& l : lights) sum += l.intensity * l.colour;
    if (luminance(sum) > 0.0) fluenceTint_ = sum / luminance(sum);
    for (const Grid<float, 3>& t : transmittance) lightT_.push_back(t.data().data());
  }

  // The distance grid's solids, the floor, then anything nearer in the BVH.
  bool opaqueHit(const Ray& ray, double tMax, SurfaceHit& hit) const override {
    double tSurface = tMax, t0, t1;
    bool found = false, sampled = false;  // sampled: the nearest so far is the distance grid's
    if (distance_ && intersectBox(ray, lo_, hi_, t0, t1) && t0 < tMax &&
        traceDistance(sampler_, distance_, ray, t0, std::min(t1, tMax), ds_, tSurface)) {
      found = sampled = true;
      const Vec3 p = ray.origin + tSurface * ray.direction;
      Vec3 g = Vec3::Zero();  // gradient of the trilinear distance, central differences over a cell
      for (int a = 0; a < 3; ++a) {
        const Vec3 e = 0.5 * dx_ * Vec3::Unit(a);
        g[a] = sampler_.at(p + e)(distance_) - sampler_.at(p - e)(distance_);
      }
      // A ray entering the box inside a solid (one that meets the domain's side) sees the box face.
      hit.normal = tSurface == t0 && t0 > 0.0 ? entryFaceNormal(ray, lo_, hi_)
                   : g.norm() > 0.0           ? Vec3(g.normalized())
                                              : Vec3(-ray.direction);
      if (hit.normal.dot(ray.direction) > 0.0) hit.normal = -hit.normal;
      hit.offsetNormal = hit.normal;
      hit.albedo = settings_.surfaceAlbedo;
      hit.t = tSurface;
    }
    if (settings_.floor.intersect(ray, tSurface, hit)) {
      found = true;
      sampled = false;
      tSurface = hit.t;
    }
    // A mesh up to a quarter cell behind a sampled solid's surface is drawn in front of it: the
    // distance is trilinear between cell centres, good to a fraction of a cell, while a mesh is
    // exact (a cloth resting on a body would otherwise show the body through it in dots).
    if (!surfaces_.empty()) {
      const double reach = sampled ? std::min(tMax, tSurface + 0.25 * dx_) : tSurface;
      if (surfaces_.intersect(ray, reach, hit)) found = true;
    }
    return found;
  }

  // Lambertian radiance of a surface point p (eq. 5.8's boundary radiance), see the header.
  Vec3 opaqueRadiance(const Vec3& p, const SurfaceHit& hit) const override {
    ++surfaceHits_;
    Vec3 L = hit.albedo.cwiseProduct(settings_.ambient);
    const Vec3 lightSample = p + 2.0 * dx_ * hit.normal, shadowOrigin = p + 1e-4 * dx_ * hit.offsetNormal;
    for (std::size_t l = 0; l < lights_.size(); ++l) {
      const LightSample s = illuminate(lights_[l], p, 0.5 * dx_);
      const double cosine = hit.normal.dot(s.toLight);
      if (!(cosine > 0.0)) continue;
      const double Tl = gridTransmittance(l, lightSample, s.toLight, s.distance);
      if (!(Tl > 0.0) || surfaces_.occluded(shadowOrigin, s.toLight, s.distance)) continue;
      Vec3 E = s.irradiance;
      if (liquid_) E = E.cwiseProduct(liquid_->lightTransmittance(shadowOrigin, s.toLight, s.distance));
      L += (cosine * Tl / std::numbers::pi) * hit.albedo.cwiseProduct(E);
    }
    return L;
  }

  // Eq. 5.8 marched front to back over [0, tEnd] inside the box (see the header).
  Segment medium(const Ray& ray, double tEnd) const override {
    Segment out;
    double t0, t1;
    if (!intersectBox(ray, lo_, hi_, t0, t1) || !(t0 < tEnd)) return out;
    t1 = std::min(t1, tEnd);
    // Per ray: irradiance * phase / 4 pi of each directional light (constant along a ray).
    thread_local std::vector<Vec3> directional;
    directional.assign(lights_.size(), Vec3::Zero());
    for (std::size_t l = 0; l < lights_.size(); ++l)
      if (lights_[l].type == Light::Type::Directional)
        // mu between the light's and the seen light's directions of travel (towards the camera).
        directional[l] = lights_[l].intensity * lights_[l].colour *
                         (phase_(lights_[l].direction.normalized().dot(-ray.direction)) * kInv4Pi);
    const double sigmaT = medium_.extinction, sigmaS = medium_.albedo * medium_.extinction;
    Vec3& radiance = out.radiance;
    double& T = out.transmittance;
    long long samples = 0;
    const long long steps = static_cast<long long>(std::ceil((t1 - t0) / ds_));
    for (long long k = 0; k < steps;) {
      const double a = t0 + k * ds_, b = std::min(a + ds_, t1), len = b - a, tm = 0.5 * (a + b);
      const Vec3 x = ray.origin + tm * ray.direction;
      double tExit;
      if (occupancy_.emptyExit(x, ray.direction, tm, tExit)) {
        // Next step whose midpoint is past the brick (samples in it add exactly nothing).
        k = std::max(k + 1, static_cast<long long>(std::ceil((tExit - t0) / ds_ - 0.5)));
        continue;
      }
      ++k;
      ++samples;
      const Trilinear w = sampler_.at(x);
      const double rho = std::max(w(rho_), 0.0f);
      Vec3 source = Vec3::Zero();  // sigma_t rho J of eq. 5.9, per metre
      if (blackbody_) {
        const double amount = emissionWeight_ * (emitter_ ? std::max(w(emitter_), 0.0f) : rho);
        if (amount > 0.0) {
          const auto bb = (*blackbody_)(w(temperature_));
          source += amount * Vec3(bb[0], bb[1], bb[2]);
        }
      }
      if (rho > 0.0 && sigmaS > 0.0) {
        Vec3 inScatter = settings_.ambient;
        for (std::size_t l = 0; l < lights_.size(); ++l) {
          const double Tl = w(lightT_[l]);
          if (lights_[l].type == Light::Type::Directional) {
            inScatter += Tl * directional[l];
          } else if (Tl > 0.0) {
            const LightSample s = illuminate(lights_[l], x, 0.5 * dx_);
            inScatter += (Tl * phase_(s.toLight.dot(ray.direction)) * kInv4Pi) * s.irradiance;
          }
        }
        if (fluence_) inScatter += (w(fluence_) * kInv4Pi) * fluenceTint_;
        source += sigmaS * rho * inScatter;
      }
      // Exact integral over the step of a constant medium: int_0^len exp(-sigma_t rho u) du.
      const double tau = sigmaT * rho * len;
      const double segmentT = std::exp(-tau);
      const double weight = tau > 1e-6 ? (1.0 - segmentT) / (sigmaT * rho) : len * (1.0 - 0.5 * tau);
      radiance += (T * weight) * source;
      T *= segmentT;
      if (T < kMinTransmittance) break;
    }
    samples_ += samples;
    return out;
  }

  Vec3 sky(const Vec3& direction) const override {
    return settings_.sky.radiance(direction, lights_, settings_.background);
  }

  long long samples() const { return samples_.load(); }
  long long surfaceHits() const { return surfaceHits_.load(); }

 private:
  // T_l of a surface point's light sample x' (see the header): the grid at the point where the path
  // from x' to the light enters the box, 1 if it misses the box (no medium, no solids outside it).
  double gridTransmittance(std::size_t l, const Vec3& x, const Vec3& toLight, double lightDistance) const {
    double a, b;
    if (!intersectBox({x, toLight}, lo_, hi_, a, b) || !(a < lightDistance)) return 1.0;
    return static_cast<double>(sampler_.at(x + a * toLight)(lightT_[l]));
  }

  const std::vector<Light>& lights_;
  const Medium& medium_;
  const VolumeRenderSettings& settings_;
  const SurfaceScene& surfaces_;
  const LiquidTracer* liquid_;
  const Occupancy occupancy_;
  const Sampler sampler_;
  Vec3 lo_, hi_;
  double dx_, ds_;
  HenyeyGreenstein phase_;
  const float *rho_, *temperature_, *emitter_, *fluence_, *distance_;
  std::optional<BlackbodyTable> blackbody_;
  double emissionWeight_ = 0.0;
  Vec3 fluenceTint_ = Vec3::Ones();
  std::vector<const float*> lightT_;
  mutable std::atomic<long long> samples_{0}, surfaceHits_{0};
};

}  // namespace

RenderResult renderVolume(const VolumeInput& input, const Camera& camera, const std::vector<Light>& lights,
                          const Medium& medium, const VolumeRenderSettings& settings) {
  input.validate();
  medium.validate();
  settings.validate();
  checkLights(lights);
  const CameraRays rays(camera);
  const SurfaceScene surfaces(input.meshes, input.points, settings.meshAlbedo);
  checkCameraOutsideSolids(camera.position, input.surfaceDistance, input.meshes);
  const Grid<float, 3>& density = *input.density;
  RenderResult result;

  auto start = std::chrono::steady_clock::now();
  std::vector<Grid<float, 3>> computed;
  if (!input.transmittances) {
    computed.reserve(lights.size());
    for (const Light& l : lights)
      computed.push_back(lightTransmittance(density, l, medium, settings.stepCells, input.surfaceDistance));
  } else if (input.transmittances->size() != lights.size()) {
    throw std::invalid_argument("volume renderer: " + std::to_string(input.transmittances->size()) +
                                " transmittance grids for " + std::to_string(lights.size()) + " lights");
  }
  const std::vector<Grid<float, 3>>& transmittance = input.transmittances ? *input.transmittances : computed;
  result.stats.secondsLightGrids = secondsSince(start);

  start = std::chrono::steady_clock::now();
  std::optional<LiquidSurface> liquidSurface;
  std::optional<LiquidTracer> liquid;
  if (input.liquid) {
    liquidSurface.emplace(*input.liquid, settings.stepCells);
    liquid.emplace(*liquidSurface, settings.liquid);
  }
  const VolumeScene scene(input, lights, medium, settings, transmittance, surfaces, liquid ? &*liquid : nullptr);
  result.radiance = FloatImage(camera.width, camera.height);
  parallelFor(0, static_cast<std::size_t>(camera.height), [&](std::size_t row) {
    for (int px = 0; px < camera.width; ++px) {
      const Ray ray = rays.ray(px + 0.5, static_cast<double>(row) + 0.5);
      const Vec3 radiance = liquid ? liquid->radiance(ray, scene) : tracedRadiance(ray, scene);
      float* out = result.radiance.pixel(px, static_cast<int>(row));
      for (int ch = 0; ch < 3; ++ch) out[ch] = static_cast<float>(radiance[ch]);
    }
  }, 1);

  FloatImage display = result.radiance;
  for (float& v : display.rgb) {
    const float x = static_cast<float>(settings.exposure) * v;
    v = settings.toneMap ? x / (1.0f + x) : x;
  }
  result.image = display.toImage8(settings.gamma);
  result.stats.secondsMarch = secondsSince(start);
  result.stats.primaryRays = static_cast<long long>(camera.width) * camera.height;
  result.stats.samples = scene.samples();
  result.stats.surfaceHits = scene.surfaceHits();
  return result;
}

}  // namespace msim::render
