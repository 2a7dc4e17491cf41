#pragma once
// What the granular stress solve (stress_solver.hpp) reads at the start of a step: the material
// on the grid, from the particles, and the rigid bodies coupled to it (Narain 2011 ch. 5.3.4).
#include <vector>

#include <Eigen/Core>

#include "msim/core/grid_spec.hpp"
#include "msim/granular/stress_lattice.hpp"

namespace msim::granular {

// A rigid body as the stress sees it (generalized 6-vectors: force then moment about `centre`).
struct CoupledBody {
  Eigen::Matrix<double, 6, 6> inverseMass = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> velocity = Eigen::Matrix<double, 6, 1>::Zero();  // V~ without stress
  Vec3 centre = Vec3::Zero();
  std::vector<double> cellFraction;  // phi_s per cell (the body's covered volume fraction)
  FaceField faceFraction;            // phi_s per face (averaged from the cells on either side)
  // The cells where cellFraction may be nonzero (the faces: the same box, one further along the
  // face's axis); the whole grid unless the rasterisation narrowed it.
  LatticeBox cells{IVec3::Zero(), IVec3::Constant(1 << 29)};
  // The faces of `axis` where faceFraction may be nonzero, within a grid of `res` cells.
  LatticeBox faces(int axis, const IVec3& res) const {
    IVec3 last = cells.last;
    last[axis] += 1;
    IVec3 size = res;
    size[axis] += 1;
    return LatticeBox{cells.first.cwiseMax(IVec3::Zero()), last.cwiseMin(size - IVec3::Ones())};
  }
};

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

}  // namespace msim::granular
