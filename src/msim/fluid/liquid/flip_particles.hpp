#pragma once
// FlipParticles<D>: the particles of a PIC/FLIP liquid (Zhu & Bridson 2005, as Golas ch. 2.7
// blends them). The particles carry the liquid and its velocity; the grid only solves for the
// pressure:
//   toGrid     velocity splatted onto the faces (D-linear weights, normalised by the weights);
//   fromGrid   v_p <- r (v_p + u_new(x_p) - u_old(x_p)) + (1 - r) u_new(x_p), r the FLIP ratio:
//              r = 1 is FLIP (only the change moves to the particles, no numerical dissipation),
//              r = 0 is PIC (the grid velocity, smoothed at every transfer);
//   advect     positions by the grid velocity (midpoint rule), kept inside the domain; one that
//              ends inside an obstacle, or in a cell the grid counts as solid (its centre is
//              inside), is pushed back out along the distance's gradient, so that it slides
//              along the wall and stays where the pressure and the surface see it;
//   surface    phi at the cell centres from the particles (Zhu & Bridson's averaged spheres:
//              phi(x) = |x - x_bar| - r, x_bar the mean position of the particles within R,
//              weighted by k(s) = max(0, 1 - s^2)^3, s = |x - x_p| / R), with R = 2 dx and
//              r = R / 4: the kernel-weighted mean depth of a half ball is 0.246 R in 3D and
//              0.259 R in 2D, so a flat, evenly filled layer gets its surface on its top.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "msim/core/block_placement.hpp"
#include "msim/core/index_box.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/transfer.hpp"
#include "msim/numerics/pressure/projection.hpp"

namespace msim::fluid {

template <int D>
class FlipParticles {
 public:
  // perCell particles per liquid cell when seeding (0: 4 in 2D, 8 in 3D: two per axis).
  FlipParticles(const GridSpec<D>& spec, int perCell, std::uint64_t seed);

  // Fills the cells with phi < 0 (and no solid) with jittered particles at the grid's velocity.
  void seed(const Grid<float, D>& phi, const Grid<float, D>& solid, const MacGrid<D>& velocity);
  // Particles that cross an open side of the domain leave the liquid (are deleted); walls hold
  // them in. solidDistance: the obstacles' signed distance (any sample layout, negative inside),
  // or null without obstacles; solid: the cells counted as solid (> 0.5).
  void advect(const MacGrid<D>& velocity, double dt, const Grid<float, D>* solidDistance, const Grid<float, D>& solid,
              const numerics::DomainSides<D>& sides = {});
  void toGrid(MacGrid<D>& velocity);
  void fromGrid(const MacGrid<D>& updated, const MacGrid<D>& before, double flipRatio);
  // phi (cell-centred) from the particles; cells far from any particle get +band, cells deep in
  // the liquid -band (the reinitialisation that follows fills in the distances).
  void surface(Grid<float, D>& phi, double bandCells) const;

  // An emitter covering the cells where region < 0: the particles in it take `velocity`, and its
  // open cells holding fewer than perCell particles are topped up (at random positions in the
  // cell, random stream `round`). Returns how many were added.
  std::size_t emit(const Grid<float, D>& region, const Grid<float, D>& solid, const Vecf<D>& velocity,
                   std::uint64_t round);
  // A sink: deletes the particles where region < 0 (D-linearly sampled); returns how many.
  std::size_t removeInside(const Grid<float, D>& region);
  // Liquid volume one particle stands for [m^3]: a cell's volume over the particles seeded per cell.
  double particleVolume() const { return spec_.cellVolume() / perCell_; }

  // Replaces the particles (a resumed run's saved ones); std::invalid_argument for mismatched
  // lengths.
  void assign(std::vector<Vecf<D>> positions, std::vector<Vecf<D>> velocities);

  // A block of a grid split among processes (core/domain_split.hpp), as for the particle level set:
  // the grid is the block with its ghost layers, at `placement`, and the particles are those in
  // the owned cells `owned`; seeding and emitters fill only the owned cells, each with
  // the random stream of its global index.
  void setBlock(const BlockPlacement<D>& placement, const IndexBox<D>& owned);
  // The particles as rows of kRowWidth doubles (position, velocity) for moving them between
  // processes: taking out those at positions x with select(x), those with select(x) copied, and
  // appending rows.
  static constexpr int kRowWidth = 2 * D;
  template <typename Select>
  std::vector<double> takeRowsIf(Select&& select);
  template <typename Select>
  std::vector<double> rowsIf(Select&& select) const;
  void appendRows(const std::vector<double>& rows);
  // The particles of other processes near the block (rows as above): the velocity's splat and
  // the surface read them with the own ones.
  void setNeighbours(const std::vector<double>& rows);

  std::size_t size() const { return positions_.size(); }
  const std::vector<Vecf<D>>& positions() const { return positions_; }
  const std::vector<Vecf<D>>& velocities() const { return velocities_; }
  double radius() const { return radius_; }

 private:
  // The own particles' positions and velocities, and the neighbours' after them when there are
  // any (what toGrid and surface read).
  std::span<const Vecf<D>> readPositions() const;
  std::span<const Vecf<D>> readVelocities() const;
  void appendRow(std::size_t p, std::vector<double>& out) const {
    out.insert(out.end(), positions_[p].data(), positions_[p].data() + D);
    out.insert(out.end(), velocities_[p].data(), velocities_[p].data() + D);
  }
  static void appendRowsTo(const std::vector<double>& rows, std::vector<Vecf<D>>& positions,
                           std::vector<Vecf<D>>& velocities);
  // Groups the particles `x` by cell (cellStart_, order_).
  void bucketByCell(std::span<const Vecf<D>> x) const;
  // Deletes the particles whose flag is set (order kept).
  std::size_t removeFlagged();

  GridSpec<D> spec_;
  int perCell_;
  std::uint64_t seed_;
  double radius_;
  std::vector<Vecf<D>> positions_, velocities_;
  BlockPlacement<D> placement_;
  IndexBox<D> owned_;  // the seeded cells
  std::size_t neighbours_ = 0;                            // neighbours' particles after the own ones in
  std::vector<Vecf<D>> withNeighbours_, withNeighboursV_;  // these
  std::vector<Vecf<D>> gatheredNew_, gatheredOld_;
  Splatter<D> splatter_;
  mutable std::vector<std::uint32_t> cellStart_, order_;  // particles grouped by cell
  mutable std::vector<std::uint32_t> cellOf_, next_;      // the grouping's work storage
  std::vector<std::uint8_t> flagged_;                     // removeFlagged()'s marks
};

template <int D>
template <typename Select>
std::vector<double> FlipParticles<D>::rowsIf(Select&& select) const {
  std::vector<double> out;
  for (std::size_t p = 0; p < positions_.size(); ++p)
    if (select(positions_[p])) appendRow(p, out);
  return out;
}

template <int D>
template <typename Select>
std::vector<double> FlipParticles<D>::takeRowsIf(Select&& select) {
  std::vector<double> out;
  flagged_.assign(positions_.size(), 0);
  for (std::size_t p = 0; p < positions_.size(); ++p)
    if ((flagged_[p] = select(positions_[p]))) appendRow(p, out);
  removeFlagged();
  return out;
}

}  // namespace msim::fluid
