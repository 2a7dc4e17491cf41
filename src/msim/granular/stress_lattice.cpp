#include "msim/granular/stress_lattice.hpp"

#include <algorithm>

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

bool insideBox(const IVec3& n, const IVec3& q) {
  return q[0] >= 0 && q[1] >= 0 && q[2] >= 0 && q[0] < n[0] && q[1] < n[1] && q[2] < n[2];
}

// The faces sample q of component c touches, with the sign of its contribution: calls
// f(face axis, face index q_f, sign). Diagonal a: +1 on its lower face-a q, -1 on the upper q + e_a.
// OffDiagonal (a, b): on face-a q - e_b with +1 and face-a q with -1 (the b-difference), and on
// face-b q - e_a with +1 and face-b q with -1 (the a-difference); edges on the domain boundary
// have only the faces that exist.
template <typename F>
void forEachLink(const StressComponent& c, const FaceField& faces, const IVec3& q, F&& f) {
  if (c.diagonal()) {
    f(c.a, q, 1.0);
    IVec3 up = q;
    up[c.a] += 1;
    f(c.a, up, -1.0);
    return;
  }
  for (const auto& [faceAxis, diffAxis] : {std::pair{c.a, c.b}, std::pair{c.b, c.a}}) {
    const IVec3 n = faces.size(faceAxis);
    IVec3 below = q;
    below[diffAxis] -= 1;
    if (insideBox(n, below)) f(faceAxis, below, 1.0);
    if (insideBox(n, q)) f(faceAxis, q, -1.0);
  }
}

}  // namespace

void addDivergence(const StressComponent& c, const std::vector<double>& s, double scale, double dx,
                   const FaceField& mask, FaceField& force) {
  // Gather form (each face reads the samples around it), so the faces can be written in parallel.
  const IVec3 lattice = latticeSize(c, force.res);
  const double k = scale / dx;
  for (int faceAxis = 0; faceAxis < 3; ++faceAxis) {
    if (c.diagonal() ? faceAxis != c.a : (faceAxis != c.a && faceAxis != c.b)) continue;
    std::vector<double>& out = force.values[faceAxis];
    const std::vector<double>& m = mask.values[faceAxis];
    parallelForCells<3>(force.size(faceAxis), [&](const IVec3& f, std::size_t i) {
      if (m[i] == 0.0) return;
      double d = 0.0;
      forEachFaceSample(c, lattice, faceAxis, f, [&](std::size_t q, double sign) { d += sign * s[q]; });
      out[i] += k * d;
    });
  }
}

void divergenceTranspose(const StressComponent& c, const FaceField& u, double dx, const FaceField& mask,
                         std::vector<double>& out) {
  const IVec3 lattice = latticeSize(c, u.res);
  out.assign(static_cast<std::size_t>(lattice[0]) * lattice[1] * lattice[2], 0.0);
  const double k = 1.0 / dx;
  parallelForCells<3>(lattice, [&](const IVec3& q, std::size_t i) {
    double sum = 0.0;
    forEachLink(c, u, q, [&](int axis, const IVec3& f, double sign) {
      const std::size_t fi = u.index(axis, f);
      if (mask.values[axis][fi] != 0.0) sum += sign * u.values[axis][fi];
    });
    out[i] = k * sum;
  });
}

void poissonStencil(const StressComponent& c, const FaceField& weight, double dx, const FaceField& mask,
                    double isolated, std::array<std::vector<double>, 3>& lowerWeight, std::vector<double>& diagonal) {
  const IVec3 lattice = latticeSize(c, weight.res);
  const std::size_t count = static_cast<std::size_t>(lattice[0]) * lattice[1] * lattice[2];
  for (auto& w : lowerWeight) w.assign(count, 0.0);
  diagonal.assign(count, 0.0);
  const double k = 1.0 / (dx * dx);
  auto w = [&](int axis, const IVec3& f) {
    const std::size_t fi = weight.index(axis, f);
    return mask.values[axis][fi] != 0.0 ? weight.values[axis][fi] * k : 0.0;
  };
  parallelForCells<3>(lattice, [&](const IVec3& q, std::size_t i) {
    double d = 0.0;
    forEachLink(c, weight, q, [&](int axis, const IVec3& f, double) { d += w(axis, f); });
    diagonal[i] = d > 0.0 ? d : isolated;
    // The link to q - e_l shares one face: for a diagonal component the lower face-a (l = a); for
    // an off-diagonal one the face-a q - e_b (l = b) or the face-b q - e_a (l = a).
    for (int l = 0; l < 3; ++l) {
      if (q[l] == 0) continue;
      if (c.diagonal() && l == c.a) lowerWeight[l][i] = w(c.a, q);
      if (!c.diagonal() && (l == c.a || l == c.b)) {
        const int faceAxis = l == c.b ? c.a : c.b;
        IVec3 f = q;
        f[l] -= 1;
        if (insideBox(weight.size(faceAxis), f)) lowerWeight[l][i] = w(faceAxis, f);
      }
    }
  });
}

}  // namespace msim::granular
