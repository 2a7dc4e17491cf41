#pragma once
// ParticleLevelSet<D>: the marker particles of the particle level set method (Enright, Fedkiw,
// Ferziger & Mitchell 2002), as Selle ch. 4.4.3 tracks water with it. Particles of both signs
// sit within a band of the interface; they are carried by the flow without numerical diffusion,
// and where the level set's own advection has smeared the interface they repair it:
//
//  - seeding: in every cell of the band, particlesPerCell random positions, each with the sign of
//    phi there, attracted along the normal, x += (phi_goal - phi(x)) N(x), until phi(x) lies at
//    a random phi_goal between minSeed and maxSeed (in cells) on its own side;
//  - radius: r_p = clamp(s_p phi(x_p), minRadius, maxRadius) (s_p the sign);
//  - escaped particles: on the wrong side by more than their radius, s_p phi(x_p) < -r_p;
//  - correction: each escaped particle's sphere phi_p(x) = s_p (r_p - |x - x_p|) raises phi+
//    (positive particles, max) or lowers phi- (negative ones, min) at the samples around it,
//    starting from phi+ = phi- = phi, and the result keeps the one of smaller magnitude;
//  - reseeding: particles that left the band are deleted and cells of the band with fewer than
//    particlesPerCell particles are topped up.
// The caller advances phi (any advection scheme) and the particles by the same velocity, then
// corrects, reinitialises, corrects again and adjusts the radii (Enright's step).
// Particles live in a structure of arrays; all work is deterministic (per-cell random streams).
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "msim/core/block_placement.hpp"
#include "msim/core/index_box.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"

namespace msim::numerics {

struct ParticleLevelSetSettings {
  int particlesPerCell = 0;     // per cell of the band; 0: 16 in 2D, 32 in 3D
  double bandCells = 3.0;       // particles are seeded where |phi| < bandCells * dx
  // Radius bounds [cells]. Enright uses 0.1 and 0.5 dx; with 0.1 the surface may drift by about
  // 0.2 dx before a particle escapes, which Zalesak's disc shows as a 2.7% area loss after one
  // turn at 100^2 (0.5% with 0.02).
  double minRadiusCells = 0.02;
  double maxRadiusCells = 0.5;
  double minSeedCells = 0.02;   // phi_goal of new particles, in cells on their own side
  double maxSeedCells = 3.0;    //   (Enright: from the smallest radius to the band's edge)
  int attractionIterations = 15;
  // Reseeding also deletes the particles that are still escaped. A single-phase liquid wants this:
  // the air pockets and droplets such particles mark are below the grid or gone (a bubble in the
  // liquid collapses), and left in place they carve or pad the surface at every correction (a 2D
  // dam break lost half its water in 3 s). Pure advection keeps them: they hold the sheets thinner
  // than a cell (Enright's deformation test loses 38% instead of 3% without them).
  bool deleteEscapedOnReseed = false;
  std::uint64_t seed = 1;       // random streams (per cell and reseeding round)
};

template <int D>
class ParticleLevelSet {
 public:
  // phi lives on the cell centres of spec.
  ParticleLevelSet(const GridSpec<D>& spec, const ParticleLevelSetSettings& settings = {});

  // Removes every particle and seeds the band of phi afresh.
  void seed(const Grid<float, D>& phi);
  // Moves the particles by the MAC velocity over dt (midpoint rule, sampled D-linearly), keeping
  // them inside the domain.
  void advect(const MacGrid<D>& velocity, double dt);
  // Enright's correction of phi by the escaped particles (the own and the neighbours'); returns
  // how many of the own ones there were.
  std::size_t correct(Grid<float, D>& phi) const;
  // r_p = clamp(s_p phi(x_p), minRadius, maxRadius).
  void adjustRadii(const Grid<float, D>& phi);
  // Deletes particles out of the band (and the escaped ones, with deleteEscapedOnReseed), tops the
  // band's cells up to particlesPerCell (new particles attracted and sized as in seed).
  void reseed(const Grid<float, D>& phi);

  // Deletes the particles where region < 0 (D-linearly sampled): liquid added or taken away there
  // by an emitter or a sink would make them escaped; the next reseeding fills the band again.
  // Returns how many.
  std::size_t removeInside(const Grid<float, D>& region);

  // A block of a grid split among processes (core/domain_split.hpp): phi's grid is the block with
  // its ghost layers, at `placement` in the global grid, and the particles are those in the owned
  // cells `owned` (local coordinates). Seeding then fills only the owned cells, each
  // with the random stream of its global index: the particles a whole grid would seed there.
  void setBlock(const BlockPlacement<D>& placement, const IndexBox<D>& owned);
  // The particles as rows of kRowWidth doubles (position, radius, sign), for moving them between
  // processes: those at positions x with select(x), and taking out those with select(x) (the
  // others keep their order); appendRows adds rows.
  static constexpr int kRowWidth = D + 2;
  template <typename Select>
  std::vector<double> rowsIf(Select&& select) const {
    std::vector<double> out;
    for (std::size_t p = 0; p < positions_.size(); ++p)
      if (select(positions_[p])) appendRow(p, out);
    return out;
  }
  template <typename Select>
  std::vector<double> takeRowsIf(Select&& select) {
    std::vector<double> out;
    keepIf([&](std::size_t p) {
      if (!select(positions_[p])) return true;
      appendRow(p, out);
      return false;
    });
    return out;
  }
  void appendRows(const std::vector<double>& rows);
  // The particles of other processes in the block's ghost layers (rows as above): correct() reads
  // them with the own ones, so an owned cell is corrected by every particle near it.
  void setNeighbours(std::vector<double> rows) { neighbours_ = std::move(rows); }

  // Replaces the particles (a resumed run's saved ones); std::invalid_argument for mismatched
  // lengths.
  void assign(std::vector<Vec<D>> positions, std::vector<float> radii, std::vector<std::int8_t> signs);

  std::size_t size() const { return positions_.size(); }
  const std::vector<Vec<D>>& positions() const { return positions_; }
  const std::vector<float>& radii() const { return radii_; }
  const std::vector<std::int8_t>& signs() const { return signs_; }
  int particlesPerCell() const { return perCell_; }

 private:
  // Keeps the particles p with keep(p) (order kept); returns how many went.
  template <typename Keep>
  std::size_t keepIf(Keep&& keep) {
    std::size_t kept = 0;
    for (std::size_t p = 0; p < positions_.size(); ++p) {
      if (!keep(p)) continue;
      positions_[kept] = positions_[p];
      radii_[kept] = radii_[p];
      signs_[kept] = signs_[p];
      ++kept;
    }
    const std::size_t removed = positions_.size() - kept;
    positions_.resize(kept);
    radii_.resize(kept);
    signs_.resize(kept);
    return removed;
  }
  void appendRow(std::size_t p, std::vector<double>& out) const {
    out.insert(out.end(), positions_[p].data(), positions_[p].data() + D);
    out.push_back(radii_[p]);
    out.push_back(signs_[p]);
  }
  // Appends up to `count` particles in cell c (random stream `stream`), attracted to phi.
  void seedCell(const Grid<float, D>& phi, const IVec<D>& c, int count, std::uint64_t stream);

  GridSpec<D> spec_;
  ParticleLevelSetSettings settings_;
  int perCell_;
  BlockPlacement<D> placement_;
  IndexBox<D> owned_;  // the seeded cells
  std::vector<double> neighbours_;               // other processes' particles (rows)
  std::uint64_t round_ = 0;  // reseeding rounds so far (new random streams each round)
  std::vector<Vec<D>> positions_;
  std::vector<float> radii_;
  std::vector<std::int8_t> signs_;
  // correct()'s work storage, kept so that steady stepping allocates nothing.
  mutable std::vector<std::size_t> escaped_;
  std::vector<int> cellCount_;  // reseed()'s particles per cell
  mutable Grid<float, D> plus_, minus_;
};

}  // namespace msim::numerics
