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
};

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
