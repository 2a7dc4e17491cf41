#pragma once
// What the granular stress solve (stress_solver.hpp) reads at the start of a step: the material
// on the grid, from the particles, and the rigid bodies coupled to it (Narain 2011 ch. 5.3.4).
#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross (faceDirection)

#include "msim/core/grid_spec.hpp"
#include "msim/granular/stress_lattice.hpp"

namespace msim::granular {

// A rigid body as the stress sees it (generalized 6-vectors: force then moment about `centre`).
// Its covered fractions are stored over the box of cells it may cover only (a paddle wheel's box
// holds about 20k of the scene's 250k cells; full-grid arrays meant zeroing 8 MB per body and step).
struct CoupledBody {
  Eigen::Matrix<double, 6, 6> inverseMass = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> velocity = Eigen::Matrix<double, 6, 1>::Zero();  // V~ without stress
  Vec3 centre = Vec3::Zero();
  // The cells where the covered fraction may be nonzero (within the grid); the faces: the same box,
  // one further along the face's axis.
  LatticeBox cells;
  std::vector<double> cellFraction;                // phi_s per cell of `cells`, x fastest
  std::array<std::vector<double>, 3> faceFraction;  // phi_s per face of faces(a), x fastest

  // Sets the box (clipped to a grid of `gridCells`) and zeroes the fractions (keeping the storage).
  void cover(const IVec3& gridCells, const LatticeBox& box) {
    cells = box.intersect(LatticeBox::whole(gridCells));
    cellFraction.assign(count(cells), 0.0);
    for (int a = 0; a < 3; ++a) faceFraction[a].assign(count(faces(a)), 0.0);
  }
  // The faces of `axis` where the face fraction may be nonzero.
  LatticeBox faces(int axis) const {
    if (cells.empty()) return cells;
    IVec3 last = cells.last;
    last[axis] += 1;
    return LatticeBox{cells.first, last};
  }
  // Index into cellFraction (faceFraction[axis]) of a cell (face) inside cells (faces(axis)).
  static std::size_t local(const LatticeBox& box, const IVec3& q) {
    const IVec3 n = box.last - box.first + IVec3::Ones(), d = q - box.first;
    return (static_cast<std::size_t>(d[2]) * n[1] + d[1]) * n[0] + d[0];
  }
  // phi_s of cell q, or of face q of `axis` (0 outside the box).
  double cellFractionAt(const IVec3& q) const { return inside(cells, q) ? cellFraction[local(cells, q)] : 0.0; }
  double faceFractionAt(int axis, const IVec3& q) const {
    const LatticeBox box = faces(axis);
    return inside(box, q) ? faceFraction[axis][local(box, q)] : 0.0;
  }

 private:
  static std::size_t count(const LatticeBox& box) {
    return box.empty() ? 0 : (box.last - box.first + IVec3::Ones()).cast<std::size_t>().prod();
  }
  static bool inside(const LatticeBox& box, const IVec3& q) {
    return (q.array() >= box.first.array()).all() && (q.array() <= box.last.array()).all();
  }
};

// G_f = [e_a; (x_f - c) x e_a] (eqs. 5.21-5.22): the generalized direction of face `f` of `axis`
// (x_f its centre) about the body's centre c.
inline Eigen::Matrix<double, 6, 1> faceDirection(const GridSpec<3>& spec, const CoupledBody& body, int axis,
                                                 const IVec3& f) {
  Vec3 x = spec.origin + (f.cast<double>().array() + 0.5).matrix() * spec.dx;
  x[axis] -= 0.5 * spec.dx;
  Eigen::Matrix<double, 6, 1> g;
  g.head<3>() = Vec3::Unit(axis);
  g.tail<3>() = Vec3(x - body.centre).cross(Vec3(Vec3::Unit(axis)));
  return g;
}

// phi_s of all the bodies together at cell q, or at face q of `axis`.
inline double coveredCellFraction(const std::vector<const CoupledBody*>& bodies, const IVec3& q) {
  double solid = 0.0;
  for (const CoupledBody* b : bodies) solid += b->cellFractionAt(q);
  return solid;
}
inline double coveredFaceFraction(const std::vector<const CoupledBody*>& bodies, int axis, const IVec3& q) {
  double solid = 0.0;
  for (const CoupledBody* b : bodies) solid += b->faceFractionAt(axis, q);
  return solid;
}

// f(linear index, coordinates) for every element of `box` in a grid of size n, in linear order.
template <typename F>
void forEachInBox(const LatticeBox& box, const IVec3& n, F&& f) {
  if (box.empty()) return;
  for (int z = box.first[2]; z <= box.last[2]; ++z)
    for (int y = box.first[1]; y <= box.last[1]; ++y)
      for (int x = box.first[0]; x <= box.last[0]; ++x)
        f((static_cast<std::size_t>(z) * n[1] + y) * n[0] + x, IVec3(x, y, z));
}

// The granular material on the grid at the start of a step (from the particles).
struct GranularGridState {
  GridSpec<3> spec;
  std::vector<double> phi;    // cells: volume fraction sum m_i / rho_max,i / V (ch. 5.5.2)
  std::vector<double> alpha;  // cells: friction coefficient (volume-weighted over materials)
  FaceField phiFace;          // faces: volume fraction
  FaceField rhoFace;          // faces: density [kg/m^3]
  FaceField open;             // faces: 1 where the velocity is free, 0 on walls (domain, static solids)
};

// A face where a body meets the grid: open, with covered fraction phi_s > 0 and direction G_f.
struct BodyFace {
  int axis;
  std::size_t index;  // in the face grid of `axis`
  IVec3 face;
  double fraction;
  Eigen::Matrix<double, 6, 1> direction;
};

// The body's faces with phi_s > 0 that st.open leaves open, by axis and then in linear order: the
// faces its coupling acts on (the solver's impulses and every problem's body columns), found once
// per step.
inline void collectBodyFaces(const GranularGridState& st, const CoupledBody& body, std::vector<BodyFace>& out) {
  out.clear();
  for (int a = 0; a < 3; ++a)
    forEachInBox(body.faces(a), st.open.size(a), [&](std::size_t i, const IVec3& f) {
      const double fraction = body.faceFractionAt(a, f);
      if (fraction <= 0.0 || st.open.values[a][i] == 0.0) return;
      out.push_back({a, i, f, fraction, faceDirection(st.spec, body, a, f)});
    });
}

}  // namespace msim::granular
