#include "msim/parallel/distributed_projection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace msim::parallel {

namespace {

// hypre's 7-point stencil: the cell, then its lower and upper neighbour along x, y, z.
constexpr int kStencilSize = 7;
constexpr int kOffsets[kStencilSize][3] = {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};

// f(local cell, owned-cell ordinal) over the owned cells, x fastest (hypre's box order).
template <typename F>
void forOwnedCells(const GridBlock<3>& block, F&& f) {
  const IndexBox<3> owned = block.ownedLocal();
  std::size_t k = 0;
  for (int z = owned.lo[2]; z < owned.hi[2]; ++z)
    for (int y = owned.lo[1]; y < owned.hi[1]; ++y)
      for (int x = owned.lo[0]; x < owned.hi[0]; ++x, ++k) f(IVec<3>(x, y, z), k);
}

}  // namespace

DistributedProjection::DistributedProjection(const GridBlock<3>& block, const numerics::DomainSides<3>& sides,
                                             const numerics::PcgSettings& settings, MPI_Comm comm,
                                             float minOpenFraction)
    : block_(block),
      origin_(block.cellOrigin()),
      sides_(sides),
      settings_(settings),
      comm_(comm),
      minOpenFraction_(minOpenFraction),
      solidVelocity_(block.localSpec(), 0.0f),
      velocityGhosts_(block, comm),
      weightGhosts_(block, comm),
      cellGhosts_(block, IVec<3>::Zero(), comm),
      phiGhosts_(block, IVec<3>::Zero(), comm),
      scaled_(block.localSpec()) {
  if (block.ghost < 1) throw std::invalid_argument("distributed projection: blocks need at least one ghost layer");
  setOpenFractions(MacGrid<3>(block.localSpec(), 1.0f));
}

DistributedProjection::~DistributedProjection() { destroyHypre(); }

void DistributedProjection::destroyHypre() {
  if (pcg_) HYPRE_StructPCGDestroy(pcg_);
  if (pfmg_) HYPRE_StructPFMGDestroy(pfmg_);
  if (x_) HYPRE_StructVectorDestroy(x_);
  if (b_) HYPRE_StructVectorDestroy(b_);
  if (matrix_) HYPRE_StructMatrixDestroy(matrix_);
  if (stencil_) HYPRE_StructStencilDestroy(stencil_);
  if (grid_) HYPRE_StructGridDestroy(grid_);
  pcg_ = pfmg_ = nullptr;
  x_ = b_ = nullptr;
  matrix_ = nullptr;
  stencil_ = nullptr;
  grid_ = nullptr;
}

void DistributedProjection::setSolidVelocity(const MacGrid<3>& solidVelocity) {
  solidVelocity_ = solidVelocity;
  velocityGhosts_.exchange(solidVelocity_);
  applyWallVelocities();
}

void DistributedProjection::setWallFaceVelocity(const MacGrid<3>* velocity) {
  if (velocity)
    wallFaceVelocity_ = *velocity;
  else
    wallFaceVelocity_.reset();
  applyWallVelocities();
}

void DistributedProjection::setWallNormalVelocity(int axis, int side, double velocity) {
  wallNormalVelocity_[static_cast<std::size_t>(axis)][static_cast<std::size_t>(side)] = static_cast<float>(velocity);
  applyWallVelocities();
}

int DistributedProjection::wallSide(int axis, const IVec<3>& face) const {
  const IVec<3> g = face + origin_;
  for (int side = 0; side < 2; ++side)
    if (g[axis] == (side == 0 ? 0 : block_.global.res[axis]) && sides_.side[axis][side] == numerics::DomainSide::Wall)
      return side;
  return -1;
}

void DistributedProjection::applyWallVelocities() {
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& us = solidVelocity_.component(a);
    for (std::size_t i = 0; i < us.count(); ++i) {
      const int side = wallSide(a, us.coord(i));
      if (side >= 0)
        us[i] = wallNormalVelocity_[static_cast<std::size_t>(a)][static_cast<std::size_t>(side)] +
                (wallFaceVelocity_ ? wallFaceVelocity_->component(a)[i] : 0.0f);
    }
  }
}

void DistributedProjection::setOpenFractions(const MacGrid<3>& openFraction) {
  weights_ = MacGrid<3>(block_.localSpec());
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& w = weights_.component(a);
    const Grid<float, 3>& open = openFraction.component(a);
    for (std::size_t i = 0; i < w.count(); ++i)
      w[i] = wallSide(a, w.coord(i)) < 0 && open[i] >= minOpenFraction_ ? std::min(open[i], 1.0f) : 0.0f;
  }
  weightGhosts_.exchange(weights_);
  if (inverseTheta_.spec() != weights_.spec()) inverseTheta_ = MacGrid<3>(block_.localSpec(), 1.0f);
  assemble();
}

void DistributedProjection::setFreeSurface(const Grid<float, 3>& liquidPhi, float minTheta) {
  liquidPhi_ = liquidPhi;
  phiGhosts_.exchange(*liquidPhi_);
  const Grid<float, 3>& phi = *liquidPhi_;
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& it = inverseTheta_.component(a);
    for (std::size_t i = 0; i < it.count(); ++i) {
      const IVec<3> f = it.coord(i), low = f - IVec<3>::Unit(a);
      it[i] = 1.0f;
      if (!phi.inside(f) || !phi.inside(low)) continue;
      const float up = phi(f), lo = phi(low);
      if ((up < 0.0f) == (lo < 0.0f)) continue;
      const float wet = up < 0.0f ? up : lo, dry = up < 0.0f ? lo : up;
      it[i] = 1.0f / std::max(minTheta, wet / (wet - dry));  // as the serial projection's theta
    }
  }
  assemble();
}

DistributedProjection::FaceTerm DistributedProjection::faceTerm(const IVec<3>& l, int axis, int side) const {
  const IVec<3> face = side ? (l + IVec<3>::Unit(axis)).eval() : l;
  const int g = l[axis] + origin_[axis];
  const bool inDomain = side ? g + 1 < block_.global.res[axis] : g > 0;
  const IVec<3> across = side ? (l + IVec<3>::Unit(axis)).eval() : (l - IVec<3>::Unit(axis)).eval();
  const bool coupled = inDomain && (!liquidPhi_ || (*liquidPhi_)(across) < 0.0f);
  return {weights_.component(axis)(face), coupled, inverseTheta_.component(axis)(face), across};
}

void DistributedProjection::assemble() {
  destroyHypre();
  const IndexBox<3> owned = block_.owned();
  const IVec<3> origin = block_.cellOrigin(), res = block_.global.res;
  const std::size_t cells = static_cast<std::size_t>(owned.count());
  coefficients_.assign(cells * kStencilSize, 0.0);
  fluid_.assign(cells, 0);
  int dirichlet = 0;  // some face of an owned cell opens onto an open domain side or air
  forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
    double* row = coefficients_.data() + k * kStencilSize;
    const bool air = liquidPhi_ && (*liquidPhi_)(l) >= 0.0f;
    for (int a = 0; a < 3 && !air; ++a)
      for (int side = 0; side < 2; ++side) {
        const FaceTerm t = faceTerm(l, a, side);
        row[0] += t.weight * (t.coupled ? 1.0 : t.scale);
        row[1 + 2 * a + side] = t.coupled ? -t.weight : 0.0;
        dirichlet |= !t.coupled && t.weight > 0.0;
      }
    fluid_[k] = row[0] > 0.0;
    if (!fluid_[k]) row[0] = 1.0;  // inside a solid or air: no unknown, p^ = 0
  });
  // Without a Dirichlet face anywhere the constants are a null space: pin the first fluid cell.
  int anyDirichlet = 0;
  MPI_Allreduce(&dirichlet, &anyDirichlet, 1, MPI_INT, MPI_MAX, comm_);
  long long firstFluid = std::numeric_limits<long long>::max();
  forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
    const IVec<3> g = l + origin;
    if (fluid_[k]) firstFluid = std::min(firstFluid, g[0] + res[0] * (g[1] + static_cast<long long>(res[1]) * g[2]));
  });
  pinned_ = pinnedOrdinal_ = -1;
  if (!anyDirichlet) {
    MPI_Allreduce(MPI_IN_PLACE, &firstFluid, 1, MPI_LONG_LONG, MPI_MIN, comm_);
    pinned_ = firstFluid == std::numeric_limits<long long>::max() ? -1 : firstFluid;
    forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
      const IVec<3> g = l + origin;
      if (g[0] + res[0] * (g[1] + static_cast<long long>(res[1]) * g[2]) != pinned_) return;
      coefficients_[k * kStencilSize] *= 2.0;  // A + d e e^T: the solution moves by a constant only
      pinnedOrdinal_ = static_cast<long long>(k);
    });
  }

  int lower[3], upper[3];
  for (int a = 0; a < 3; ++a) {
    lower[a] = owned.lo[a];
    upper[a] = owned.hi[a] - 1;  // hypre's boxes are inclusive
  }
  HYPRE_StructGridCreate(comm_, 3, &grid_);
  HYPRE_StructGridSetExtents(grid_, lower, upper);
  HYPRE_StructGridAssemble(grid_);
  HYPRE_StructStencilCreate(3, kStencilSize, &stencil_);
  for (int e = 0; e < kStencilSize; ++e) HYPRE_StructStencilSetElement(stencil_, e, const_cast<int*>(kOffsets[e]));
  HYPRE_StructMatrixCreate(comm_, grid_, stencil_, &matrix_);
  HYPRE_StructMatrixInitialize(matrix_);
  int entries[kStencilSize];
  for (int e = 0; e < kStencilSize; ++e) entries[e] = e;
  HYPRE_StructMatrixSetBoxValues(matrix_, lower, upper, kStencilSize, entries, coefficients_.data());
  HYPRE_StructMatrixAssemble(matrix_);
  for (HYPRE_StructVector* v : {&b_, &x_}) {
    HYPRE_StructVectorCreate(comm_, grid_, v);
    HYPRE_StructVectorInitialize(*v);
    HYPRE_StructVectorAssemble(*v);
  }
  // CG preconditioned by one V-cycle of PFMG with symmetric red-black Gauss-Seidel (a symmetric
  // preconditioner, as CG needs).
  HYPRE_StructPFMGCreate(comm_, &pfmg_);
  HYPRE_StructPFMGSetMaxIter(pfmg_, 1);
  HYPRE_StructPFMGSetTol(pfmg_, 0.0);
  HYPRE_StructPFMGSetZeroGuess(pfmg_);
  HYPRE_StructPFMGSetRelaxType(pfmg_, 2);
  HYPRE_StructPFMGSetNumPreRelax(pfmg_, 1);
  HYPRE_StructPFMGSetNumPostRelax(pfmg_, 1);
  HYPRE_StructPCGCreate(comm_, &pcg_);
  HYPRE_StructPCGSetTwoNorm(pcg_, 1);
  HYPRE_StructPCGSetPrecond(pcg_, HYPRE_StructPFMGSolve, HYPRE_StructPFMGSetup, pfmg_);
  HYPRE_StructPCGSetup(pcg_, matrix_, b_, x_);
  rhs_.assign(cells, 0.0);
  values_.assign(cells, 0.0);
}

double DistributedProjection::maxResidual() {
  cellGhosts_.exchange(scaled_);
  // A's rows as assembled (the pinned cell's doubled diagonal halved again: the residual is the
  // unmodified system's), each neighbour read through its offset in the local grid.
  const IVec<3> res = scaled_.spec().res;
  const std::ptrdiff_t stride[3] = {1, res.x(), static_cast<std::ptrdiff_t>(res.x()) * res.y()};
  const double* x = scaled_.data().data();
  double worst = 0.0;
  forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
    if (!fluid_[k]) return;
    const double* row = coefficients_.data() + k * kStencilSize;
    const std::ptrdiff_t c = static_cast<std::ptrdiff_t>(scaled_.index(l));
    double ax = (static_cast<long long>(k) == pinnedOrdinal_ ? 0.5 : 1.0) * row[0] * x[c];
    for (int a = 0; a < 3; ++a) ax += row[1 + 2 * a] * x[c - stride[a]] + row[2 + 2 * a] * x[c + stride[a]];
    worst = std::max(worst, std::abs(rhs_[k] - ax));
  });
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return worst;
}

SplitSolveStats DistributedProjection::project(MacGrid<3>& velocity, Grid<float, 3>& pressure, double dt,
                                                         double density) {
  if (!(dt > 0.0) || !(density > 0.0))
    throw std::invalid_argument("pressure projection: the step and the density must be positive");
  const double toScaled = dt / (density * block_.global.dx);
  velocityGhosts_.exchange(velocity);
  // b = dx c - dx div u*: the target divergence c (expanding gas) less the net outflow of each
  // fluid cell through its faces' open parts (u*) and closed parts (the solid's velocity).
  double sum = 0.0, count = 0.0;
  const auto flux = [&](int a, const IVec<3>& f) {
    const double w = weights_.component(a)(f);
    return w * velocity.component(a)(f) + (1.0 - w) * solidVelocity_.component(a)(f);
  };
  forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
    double outflow = 0.0;
    for (int a = 0; a < 3; ++a) outflow += flux(a, l + IVec<3>::Unit(a)) - flux(a, l);
    const double target =
        block_.global.dx * (targetDivergence_ + (cellTargetDivergence_ ? double((*cellTargetDivergence_)(l)) : 0.0));
    rhs_[k] = fluid_[k] ? target - outflow : 0.0;
    sum += rhs_[k];
    count += fluid_[k];
  });
  if (pinned_ >= 0) {  // the compatibility condition of the pure Neumann problem
    double totals[2] = {sum, count};
    MPI_Allreduce(MPI_IN_PLACE, totals, 2, MPI_DOUBLE, MPI_SUM, comm_);
    const double mean = totals[1] > 0.0 ? totals[0] / totals[1] : 0.0;
    for (std::size_t k = 0; k < rhs_.size(); ++k)
      if (fluid_[k]) rhs_[k] -= mean;
  }
  double bMax = 0.0;
  for (double b : rhs_) bMax = std::max(bMax, std::abs(b));
  MPI_Allreduce(MPI_IN_PLACE, &bMax, 1, MPI_DOUBLE, MPI_MAX, comm_);

  // Warm start from the last pressure, as the serial projection does.
  forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) { values_[k] = fluid_[k] ? pressure(l) * toScaled : 0.0; });
  const IndexBox<3> owned = block_.owned();
  int lower[3], upper[3];
  for (int a = 0; a < 3; ++a) {
    lower[a] = owned.lo[a];
    upper[a] = owned.hi[a] - 1;
  }
  HYPRE_StructVectorSetBoxValues(b_, lower, upper, rhs_.data());
  HYPRE_StructVectorSetBoxValues(x_, lower, upper, values_.data());
  SplitSolveStats stats;  // iterations: hypre's, all rounds
  const double target = settings_.tolerance * bMax;
  // hypre stops on the 2-norm; the criterion here is the max-norm, so tighten and resume until
  // it holds (usually once).
  double tolerance = settings_.tolerance;
  for (int round = 0; round < 4 && stats.iterations < settings_.maxIterations; ++round) {
    if (bMax > 0.0) {
      HYPRE_StructPCGSetTol(pcg_, tolerance);
      HYPRE_StructPCGSetMaxIter(pcg_, settings_.maxIterations - stats.iterations);
      HYPRE_StructPCGSolve(pcg_, matrix_, b_, x_);
      int iterations = 0;
      HYPRE_StructPCGGetNumIterations(pcg_, &iterations);
      stats.iterations += iterations;
    }
    HYPRE_StructVectorGetBoxValues(x_, lower, upper, values_.data());
    forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) { scaled_(l) = values_[k]; });
    const double residual = maxResidual();
    stats.relativeResidual = bMax > 0.0 ? residual / bMax : 0.0;
    if (residual <= target) break;
    tolerance *= 0.1;
  }
  stats.converged = stats.relativeResidual <= settings_.tolerance;
  if (pinned_ >= 0) {  // p^ up to a constant: keep the mean over fluid cells at 0 (as the serial solver)
    double totals[2] = {0.0, 0.0};
    forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
      totals[0] += fluid_[k] ? scaled_(l) : 0.0;
      totals[1] += fluid_[k];
    });
    MPI_Allreduce(MPI_IN_PLACE, totals, 2, MPI_DOUBLE, MPI_SUM, comm_);
    const double mean = totals[1] > 0.0 ? totals[0] / totals[1] : 0.0;
    forOwnedCells(block_, [&](const IVec<3>& l, std::size_t k) {
      if (fluid_[k]) scaled_(l) -= mean;
    });
    cellGhosts_.exchange(scaled_);
  }

  // u = u* - grad p^ on the owned open faces; closed faces take the solid's velocity.
  const IVec<3> origin = block_.cellOrigin(), res = block_.global.res;
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& u = velocity.component(a);
    const Grid<float, 3>& w = weights_.component(a);
    const IndexBox<3> faces = block_.ownedSamples(block_.rank, IVec<3>::Unit(a));
    for (int z = faces.lo[2]; z < faces.hi[2]; ++z)
      for (int y = faces.lo[1]; y < faces.hi[1]; ++y)
        for (int x = faces.lo[0]; x < faces.hi[0]; ++x) {
          const IVec<3> g(x, y, z), l = g - origin, low = l - IVec<3>::Unit(a);
          if (w(l) <= 0.0f) {
            u(l) = solidVelocity_.component(a)(l);
            continue;
          }
          // Air cells and the ghosts beyond open sides hold p^ = 0; across a liquid-air face the
          // difference is divided by theta (the ghost-fluid extrapolation to the surface).
          const double pUp = g[a] < res[a] ? scaled_(l) : 0.0, pLow = g[a] > 0 ? scaled_(low) : 0.0;
          u(l) = static_cast<float>(u(l) - (pUp - pLow) * inverseTheta_.component(a)(l));
        }
  }
  forOwnedCells(block_, [&](const IVec<3>& l, std::size_t) { pressure(l) = static_cast<float>(scaled_(l) / toScaled); });
  return stats;
}

}  // namespace msim::parallel
