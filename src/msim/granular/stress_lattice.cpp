#include "msim/granular/stress_lattice.hpp"

#include <algorithm>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim::granular {

FaceField::FaceField(const IVec3& cells, double value) : res(cells) {
  for (int a = 0; a < 3; ++a) {
    const IVec3 n = size(a);
    values[a].assign(static_cast<std::size_t>(n[0]) * n[1] * n[2], value);
  }
}

IVec3 FaceField::size(int axis) const {
  IVec3 n = res;
  n[axis] += 1;
  return n;
}

std::size_t FaceField::index(int axis, const IVec3& q) const {
  const IVec3 n = size(axis);
  return (static_cast<std::size_t>(q[2]) * n[1] + q[1]) * n[0] + q[0];
}

void FaceField::fill(double value) {
  for (auto& v : values) std::fill(v.begin(), v.end(), value);
}

void FaceField::reset(const IVec3& cells) {
  if (cells != res) {
    *this = FaceField(cells);
    return;
  }
  fill(0.0);
}

IVec3 latticeSize(const StressComponent& c, const IVec3& cells) {
  IVec3 n = cells;
  if (!c.diagonal()) {
    n[c.a] += 1;
    n[c.b] += 1;
  }
  return n;
}

namespace {

// The faces of one axis that component c acts on, as the two samples each face reads: face f of
// axis `faceAxis` gets s(f + plus) - s(f + minus) (the rows of D_c; forEachFaceSample). Two
// samples share a face only as such a pair, and the pair's upper sample q has its lower neighbour
// q - e_lowerAxis across face q - plus.
struct FaceLinks {
  int faceAxis, lowerAxis;
  IVec3 plus, minus;
};

// Diagonal a: face-a f reads s(f) - s(f - e_a). OffDiagonal (a, b): face-a f reads
// s(f + e_b) - s(f), face-b f reads s(f + e_a) - s(f).
int faceLinks(const StressComponent& c, std::array<FaceLinks, 2>& out) {
  const IVec3 zero = IVec3::Zero();
  if (c.diagonal()) {
    out[0] = {c.a, c.a, zero, -IVec3::Unit(c.a)};
    return 1;
  }
  out[0] = {c.a, c.b, IVec3::Unit(c.b), zero};
  out[1] = {c.b, c.a, IVec3::Unit(c.a), zero};
  return 2;
}

// Row (y, z) of a grid of size n seen in a grid of size m shifted by delta: element x of the row
// is element base + x of m, for x in [x0, x1) (where x + delta.x lies inside m). False if the row
// lies outside m or no x does.
struct ShiftedRow {
  std::ptrdiff_t base = 0;
  int x0 = 0, x1 = 0;
};
bool shiftRow(const IVec3& n, const IVec3& m, const IVec3& delta, int y, int z, ShiftedRow& r) {
  const int yy = y + delta[1], zz = z + delta[2];
  if (yy < 0 || yy >= m[1] || zz < 0 || zz >= m[2]) return false;
  r.base = (static_cast<std::ptrdiff_t>(zz) * m[1] + yy) * m[0] + delta[0];
  r.x0 = std::max(0, -delta[0]);
  r.x1 = std::min(n[0], m[0] - delta[0]);
  return r.x0 < r.x1;
}

// f(y, z, index of the row's first element) for every x-row of a grid of size n that crosses
// `box` (a box of that grid), in parallel (rows are independent; about 4096 elements per task).
template <typename F>
void forRows(const IVec3& n, const LatticeBox& box, const F& f) {
  if (box.empty()) return;
  const int ny = box.last[1] - box.first[1] + 1, nz = box.last[2] - box.first[2] + 1;
  const std::size_t rows = static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  const std::size_t grain = std::max<std::size_t>(1, 4096 / std::max(1, box.last[0] - box.first[0] + 1));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t row = r.begin(); row != r.end(); ++row) {
      const int y = box.first[1] + static_cast<int>(row % static_cast<std::size_t>(ny));
      const int z = box.first[2] + static_cast<int>(row / static_cast<std::size_t>(ny));
      f(y, z, (static_cast<std::size_t>(z) * n[1] + y) * static_cast<std::size_t>(n[0]));
    }
  });
}

// For the lattice row (y, z) of component c's samples: f(link, plus, row) for each face row they
// read, plus: the faces q - link.plus (read with +), else q - link.minus (read with -); row maps
// sample x to face index row.base + x for x in [row.x0, row.x1). In link order, plus first.
template <typename F>
void forEachFaceRowOfSamples(const std::array<FaceLinks, 2>& links, int count, const IVec3& lattice,
                             const FaceField& faces, int y, int z, const F& f) {
  for (int e = 0; e < count; ++e) {
    const FaceLinks& l = links[static_cast<std::size_t>(e)];
    const IVec3 n = faces.size(l.faceAxis);
    for (const bool plus : {true, false}) {
      ShiftedRow r;
      if (shiftRow(lattice, n, plus ? IVec3(-l.plus) : IVec3(-l.minus), y, z, r)) f(l, plus, r);
    }
  }
}

}  // namespace

LatticeBox facesReading(const StressComponent& c, const LatticeBox& samples, const IVec3& cells, int axis) {
  std::array<FaceLinks, 2> links;
  const int count = faceLinks(c, links);
  for (int e = 0; e < count; ++e) {
    const FaceLinks& l = links[static_cast<std::size_t>(e)];
    if (l.faceAxis != axis || samples.empty()) continue;
    // Face f reads the samples f + plus and f + minus.
    IVec3 size = cells;
    size[axis] += 1;
    const LatticeBox faces{(samples.first - l.plus.cwiseMax(l.minus)).cwiseMax(IVec3::Zero()),
                           (samples.last - l.plus.cwiseMin(l.minus)).cwiseMin(size - IVec3::Ones())};
    return faces;
  }
  return {};
}

// The three passes below run row by row: along a row the samples a face reads (and the faces a
// sample touches) sit at fixed offsets, so the inner loops only index arrays.
void addDivergence(const StressComponent& c, const std::vector<double>& s, double scale, double dx,
                   const FaceField& mask, FaceField& force) {
  addDivergence(c, s, scale, dx, mask, force, LatticeBox::whole(latticeSize(c, force.res)));
}

void addDivergence(const StressComponent& c, const std::vector<double>& s, double scale, double dx,
                   const FaceField& mask, FaceField& force, const LatticeBox& samples) {
  // Gather form (each face reads the samples around it), so the faces can be written in parallel.
  const IVec3 lattice = latticeSize(c, force.res);
  const double k = scale / dx;
  std::array<FaceLinks, 2> links;
  const int count = faceLinks(c, links);
  for (int e = 0; e < count; ++e) {
    const FaceLinks& l = links[static_cast<std::size_t>(e)];
    const IVec3 n = force.size(l.faceAxis);
    const LatticeBox faces = facesReading(c, samples, force.res, l.faceAxis);
    double* out = force.values[l.faceAxis].data();
    const double* m = mask.values[l.faceAxis].data();
    forRows(n, faces, [&](int y, int z, std::size_t row) {
      ShiftedRow hi, lo;
      if (!shiftRow(n, lattice, l.plus, y, z, hi)) hi.x0 = hi.x1 = 0;
      if (!shiftRow(n, lattice, l.minus, y, z, lo)) lo.x0 = lo.x1 = 0;
      const int x0 = std::max(std::min(hi.x0, lo.x0), faces.first[0]);
      const int x1 = std::min(std::max(hi.x1, lo.x1), faces.last[0] + 1);
      for (int x = x0; x < x1; ++x) {
        if (m[row + x] == 0.0) continue;
        const double up = x >= hi.x0 && x < hi.x1 ? s[static_cast<std::size_t>(hi.base + x)] : 0.0;
        const double down = x >= lo.x0 && x < lo.x1 ? s[static_cast<std::size_t>(lo.base + x)] : 0.0;
        out[row + x] += k * (up - down);
      }
    });
  }
}

void divergenceTranspose(const StressComponent& c, const FaceField& u, double dx, const FaceField& mask,
                         std::vector<double>& out) {
  const IVec3 lattice = latticeSize(c, u.res);
  out.assign(static_cast<std::size_t>(lattice.prod()), 0.0);
  divergenceTranspose(c, u, dx, mask, out, LatticeBox::whole(lattice));
}

void divergenceTranspose(const StressComponent& c, const FaceField& u, double dx, const FaceField& mask,
                         std::vector<double>& out, const LatticeBox& samples) {
  const IVec3 lattice = latticeSize(c, u.res);
  out.resize(static_cast<std::size_t>(lattice.prod()));
  const double k = 1.0 / dx;
  std::array<FaceLinks, 2> links;
  const int count = faceLinks(c, links);
  const int x0 = samples.first[0], x1 = samples.last[0] + 1;
  forRows(lattice, samples, [&](int y, int z, std::size_t row) {
    double* o = out.data() + row;
    for (int x = x0; x < x1; ++x) o[x] = 0.0;
    // Masked faces count as 0.
    forEachFaceRowOfSamples(links, count, lattice, u, y, z, [&](const FaceLinks& l, bool plus, const ShiftedRow& r) {
      const double* v = u.values[l.faceAxis].data();
      const double* m = mask.values[l.faceAxis].data();
      const double sign = plus ? 1.0 : -1.0;
      for (int x = std::max(r.x0, x0); x < std::min(r.x1, x1); ++x) {
        const std::size_t f = static_cast<std::size_t>(r.base + x);
        if (m[f] != 0.0) o[x] += sign * v[f];
      }
    });
    for (int x = x0; x < x1; ++x) o[x] *= k;
  });
}

void poissonStencil(const StressComponent& c, const FaceField& weight, double dx, const FaceField& mask,
                    double isolated, std::array<std::vector<double>, 3>& lowerWeight, std::vector<double>& diagonal) {
  const IVec3 lattice = latticeSize(c, weight.res);
  const std::size_t count = static_cast<std::size_t>(lattice[0]) * lattice[1] * lattice[2];
  for (auto& w : lowerWeight) w.assign(count, 0.0);
  diagonal.assign(count, 0.0);
  const double k = 1.0 / (dx * dx);
  std::array<FaceLinks, 2> links;
  const int linkCount = faceLinks(c, links);
  forRows(lattice, LatticeBox::whole(lattice), [&](int y, int z, std::size_t row) {
    double* d = diagonal.data() + row;
    forEachFaceRowOfSamples(links, linkCount, lattice, weight, y, z,
                            [&](const FaceLinks& l, bool plus, const ShiftedRow& r) {
      const double* w = weight.values[l.faceAxis].data();
      const double* m = mask.values[l.faceAxis].data();
      // The upper sample of a pair links to its lower neighbour across face q - plus (not on the
      // lattice's lower side along the link's axis).
      const int yz[3] = {0, y, z};
      double* lower = lowerWeight[l.lowerAxis].data() + row;
      const int firstX = l.lowerAxis == 0 ? 1 : 0;
      const bool setsLower = plus && (l.lowerAxis == 0 || yz[l.lowerAxis] > 0);
      for (int x = r.x0; x < r.x1; ++x) {
        const std::size_t f = static_cast<std::size_t>(r.base + x);
        const double wf = m[f] != 0.0 ? w[f] * k : 0.0;
        d[x] += wf;
        if (setsLower && x >= firstX) lower[x] = wf;
      }
    });
    for (int x = 0; x < lattice[0]; ++x)
      if (!(d[x] > 0.0)) d[x] = isolated;
  });
}

}  // namespace msim::granular
