#include "msim/crowd/stress/stress_grid.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

namespace msim::crowd::stress {

namespace {

// A cell counts as fully covered below this free fraction; partly covered ones divide by at least
// kSmallestFree (the chapter's correction 1 / (1 - phi) guarded against slivers).
constexpr float kCovered = 1e-6f;
constexpr double kSmallestFree = 0.05;

// A = scale D^T D + diag(extra), applied as D then D^T on the grid (StressGrid::divergence and
// divergenceTranspose). The unknowns with an extra diagonal couple to nothing, so its norm is the
// larger of the two blocks'. |D^T D| <= 8 / h^2: D's rows on this grid are rows of D on a periodic
// grid around it, applied to the unknowns extended by zeros, where D's symbol takes (s_d, s_o) to
// (a s_d + b s_o, a s_o - b s_d) with a, b = 2i sin(theta / 2) / h along x and y, whose square is
// |a|^2 + |b|^2 <= 8 / h^2 times the identity (half the Gershgorin bound 16 / h^2, and measured:
// 7.97 / h^2 by power iteration on the merge; MPRGP's expansion steps of 1.9 / |A| are as much
// longer).
class FrictionOperator final : public numerics::QpOperator {
 public:
  FrictionOperator(const StressGrid& grid, double scale, const Eigen::VectorXd& diagonal,
                   const Eigen::VectorXd& columnNorms, double normBound, Eigen::VectorXd& scratch)
      : grid_(grid),
        scale_(scale),
        diagonal_(diagonal),
        columnNorms_(columnNorms),
        normBound_(normBound),
        faces_(scratch) {}
  Eigen::Index size() const override { return diagonal_.size(); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    grid_.divergence(x, faces_);
    grid_.divergenceTranspose(faces_, y);
    // Unknowns no open face sees carry only the diagonal setDecoupledDiagonals gave them: their
    // zero right-hand side holds them at 0.
    for (Eigen::Index k = 0; k < y.size(); ++k)
      y[k] = columnNorms_[k] > 0.0 ? scale_ * y[k] : diagonal_[k] * x[k];
  }
  void diagonal(Eigen::VectorXd& d) const override { d = diagonal_; }
  double normUpperBound() const override { return normBound_; }

 private:
  const StressGrid& grid_;
  double scale_;
  const Eigen::VectorXd& diagonal_;
  const Eigen::VectorXd& columnNorms_;  // |column k of D|^2: 0 for the decoupled unknowns
  double normBound_;
  Eigen::VectorXd& faces_;
};

}  // namespace

StressGrid::StressGrid(const GridSpec<2>& grid)
    : grid_(grid),
      nx_(grid.res.x()),
      ny_(grid.res.y()),
      count_(grid),
      momentumX_(grid),
      momentumY_(grid),
      density_(grid),
      velocityX_(grid),
      velocityY_(grid),
      covered_(grid),
      sumX_(grid),
      sumY_(grid),
      collisionFreeX_(grid),
      collisionFreeY_(grid),
      active_(static_cast<std::size_t>((nx_ + 1) * ny_ + nx_ * (ny_ + 1)), 0) {}

void StressGrid::splat(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, const Grid<float, 2>& free,
                       std::span<const Vec2f> collisionFree) {
  if (positions.size() != velocities.size() || (!collisionFree.empty() && collisionFree.size() != positions.size()))
    throw std::invalid_argument("stress grid: positions and velocities differ in number");
  if (!(free.spec() == grid_)) throw std::invalid_argument("stress grid: the free fractions lie on another grid");
  const std::size_t n = positions.size();
  ones_.assign(n, 1.0f);
  vx_.resize(n);
  vy_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    vx_[k] = velocities[k].x();
    vy_[k] = velocities[k].y();
  }
  count_.fill(0.0f);
  momentumX_.fill(0.0f);
  momentumY_.fill(0.0f);
  splatter_.splatSums<3>(positions, {std::span<const float>(ones_), std::span<const float>(vx_), std::span<const float>(vy_)},
                         {&count_, &momentumX_, &momentumY_}, TransferKernel::Linear);
  sumX_.fill(0.0f);
  sumY_.fill(0.0f);
  if (!collisionFree.empty()) {
    cx_.resize(n);
    cy_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      cx_[k] = collisionFree[k].x();
      cy_[k] = collisionFree[k].y();
    }
    splatter_.splatSums<2>(positions, {std::span<const float>(cx_), std::span<const float>(cy_)}, {&sumX_, &sumY_},
                           TransferKernel::Linear);
  }
  const double area = grid_.dx * grid_.dx;
  std::vector<std::uint8_t>& known = known_;
  known.assign(count_.count(), 0);
  for (std::size_t c = 0; c < count_.count(); ++c) {
    const float f = free[c];
    covered_[c] = f <= kCovered ? 1.0f : 0.0f;
    if (covered_[c] != 0.0f) continue;
    known[c] = 1;
    density_[c] = static_cast<float>(count_[c] / (area * std::max<double>(f, kSmallestFree)));
    velocityX_[c] = count_[c] > 1e-6f ? momentumX_[c] / count_[c] : 0.0f;
    velocityY_[c] = count_[c] > 1e-6f ? momentumY_[c] / count_[c] : 0.0f;
    collisionFreeX_[c] = count_[c] > 1e-6f ? sumX_[c] / count_[c] : 0.0f;
    collisionFreeY_[c] = count_[c] > 1e-6f ? sumY_[c] / count_[c] : 0.0f;
  }
  // Covered cells take the density of the nearest uncovered one, layer by layer outwards (each
  // layer reads the layers before it only; ties go to the first of -x, +x, -y, +y).
  std::vector<std::uint8_t>& next = nextKnown_;
  next = known;
  for (bool grew = true; grew;) {
    grew = false;
    for (int j = 0; j < ny_; ++j)
      for (int i = 0; i < nx_; ++i) {
        const std::size_t c = density_.index(IVec<2>(i, j));
        if (known[c]) continue;
        const IVec<2> around[4] = {IVec<2>(i - 1, j), IVec<2>(i + 1, j), IVec<2>(i, j - 1), IVec<2>(i, j + 1)};
        for (const IVec<2>& a : around) {
          if (!density_.inside(a) || !known[density_.index(a)]) continue;
          density_[c] = density_(a);
          velocityX_[c] = velocityY_[c] = collisionFreeX_[c] = collisionFreeY_[c] = 0.0f;
          next[c] = 1;
          grew = true;
          break;
        }
      }
    known = next;
  }
  // Faces between two cells that are not fully covered carry momentum; the domain's walls do not.
  const auto open = [&](int i, int j) { return covered_(IVec<2>(i, j)) == 0.0f; };
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i <= nx_; ++i)
      active_[static_cast<std::size_t>(i + (nx_ + 1) * j)] = i > 0 && i < nx_ && open(i - 1, j) && open(i, j);
  const std::size_t xFaces = static_cast<std::size_t>((nx_ + 1) * ny_);
  for (int j = 0; j <= ny_; ++j)
    for (int i = 0; i < nx_; ++i)
      active_[xFaces + static_cast<std::size_t>(i + nx_ * j)] = j > 0 && j < ny_ && open(i, j - 1) && open(i, j);
  // D follows the open faces, which change only where obstacles move.
  if (active_ != builtFor_) {
    followOpenFaces();
    builtFor_ = active_;
  }
}

void StressGrid::discomfortGradient(const StressLaws& laws, MacGrid<2>& gradient) const {
  if (!(gradient.spec() == grid_)) gradient = MacGrid<2>(grid_);
  const double h = grid_.dx;
  const auto g = [&](int i, int j) { return discomfort(density_(IVec<2>(i, j)), laws); };
  Grid<float, 2>& gx = gradient.component(0);
  Grid<float, 2>& gy = gradient.component(1);
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i <= nx_; ++i)
      gx(IVec<2>(i, j)) = active_[static_cast<std::size_t>(i + (nx_ + 1) * j)]
                              ? static_cast<float>((g(i, j) - g(i - 1, j)) / h)
                              : 0.0f;
  const std::size_t xFaces = static_cast<std::size_t>((nx_ + 1) * ny_);
  for (int j = 0; j <= ny_; ++j)
    for (int i = 0; i < nx_; ++i)
      gy(IVec<2>(i, j)) = active_[xFaces + static_cast<std::size_t>(i + nx_ * j)]
                              ? static_cast<float>((g(i, j) - g(i, j - 1)) / h)
                              : 0.0f;
}

void StressGrid::divergence(const Eigen::VectorXd& stress, Eigen::VectorXd& faces) const {
  const int nx = nx_, ny = ny_;
  if (stress.size() != static_cast<Eigen::Index>(nx * ny + (nx + 1) * (ny + 1)))
    throw std::invalid_argument("stress grid: one stress per cell and corner expected");
  const double inv = 1.0 / grid_.dx;
  const double* sd = stress.data();
  const double* so = sd + static_cast<std::ptrdiff_t>(nx) * ny;
  faces.resize(static_cast<Eigen::Index>(active_.size()));
  double* fx = faces.data();
  double* fy = fx + static_cast<std::ptrdiff_t>(nx + 1) * ny;
  const std::uint8_t* ax = active_.data();
  const std::uint8_t* ay = ax + static_cast<std::ptrdiff_t>(nx + 1) * ny;
  // (div s)_x at the face between cells (i - 1, j) and (i, j), whose ends are corners (i, j), (i, j + 1).
  for (int j = 0; j < ny; ++j) {
    const double* d = sd + nx * j;
    const double* o = so + (nx + 1) * j;
    double* f = fx + (nx + 1) * j;
    const std::uint8_t* open = ax + (nx + 1) * j;
    f[0] = f[nx] = 0.0;
    for (int i = 1; i < nx; ++i) f[i] = open[i] ? inv * (d[i] - d[i - 1] + o[i + nx + 1] - o[i]) : 0.0;
  }
  // (div s)_y at the face between cells (i, j - 1) and (i, j), whose ends are corners (i, j), (i + 1, j).
  std::fill(fy, fy + nx, 0.0);
  std::fill(fy + static_cast<std::ptrdiff_t>(nx) * ny, fy + static_cast<std::ptrdiff_t>(nx) * (ny + 1), 0.0);
  for (int j = 1; j < ny; ++j) {
    const double* d = sd + nx * j;
    const double* o = so + (nx + 1) * j;
    double* f = fy + nx * j;
    const std::uint8_t* open = ay + nx * j;
    for (int i = 0; i < nx; ++i) f[i] = open[i] ? inv * (o[i + 1] - o[i] - d[i] + d[i - nx]) : 0.0;
  }
}

void StressGrid::divergenceTranspose(const Eigen::VectorXd& faces, Eigen::VectorXd& stress) const {
  if (faces.size() != static_cast<Eigen::Index>(active_.size()))
    throw std::invalid_argument("stress grid: one value per face expected");
  const int nx = nx_, ny = ny_;
  const double inv = 1.0 / grid_.dx;
  stress.resize(static_cast<Eigen::Index>(nx * ny + (nx + 1) * (ny + 1)));
  double* sd = stress.data();
  double* so = sd + static_cast<std::ptrdiff_t>(nx) * ny;
  const double* fx = faces.data();
  const double* fy = fx + static_cast<std::ptrdiff_t>(nx + 1) * ny;
  const std::uint8_t* ax = active_.data();
  const std::uint8_t* ay = ax + static_cast<std::ptrdiff_t>(nx + 1) * ny;
  // D's rows of the faces that carry no momentum are empty: their values do not enter.
  const auto value = [](const double* f, const std::uint8_t* open, std::ptrdiff_t k) { return open[k] ? f[k] : 0.0; };
  // D's columns: s_d(i, j) enters x faces (i, j) (+) and (i + 1, j) (-), y faces (i, j) (-) and
  // (i, j + 1) (+); s_o(i, j) x faces (i, j - 1) (+) and (i, j) (-), y faces (i - 1, j) (+) and
  // (i, j) (-).
  for (int j = 0; j < ny; ++j) {
    const double* x = fx + (nx + 1) * j;
    const double* y = fy + nx * j;
    const std::uint8_t* ox = ax + (nx + 1) * j;
    const std::uint8_t* oy = ay + nx * j;
    double* d = sd + nx * j;
    for (int i = 0; i < nx; ++i)
      d[i] = inv * (value(x, ox, i) - value(x, ox, i + 1) - value(y, oy, i) + value(y, oy, i + nx));
  }
  for (int j = 0; j <= ny; ++j) {
    const double* x = fx + (nx + 1) * j;  // x faces (., j), present for j < ny
    const double* y = fy + nx * j;        // y faces (., j), present for i < nx
    const std::uint8_t* ox = ax + (nx + 1) * j;
    const std::uint8_t* oy = ay + nx * j;
    double* o = so + (nx + 1) * j;
    for (int i = 0; i <= nx; ++i) {
      double sum = 0.0;
      if (j > 0) sum += value(x, ox, i - (nx + 1));
      if (j < ny) sum -= value(x, ox, i);
      if (i > 0) sum += value(y, oy, i - 1);
      if (i < nx) sum -= value(y, oy, i);
      o[i] = inv * sum;
    }
  }
}

void StressGrid::followOpenFaces() {
  // |column k of D|^2 h^2: the open faces each stress unknown enters (divergenceTranspose's list).
  const std::size_t cells = static_cast<std::size_t>(nx_ * ny_);
  const std::size_t xFaces = static_cast<std::size_t>((nx_ + 1) * ny_);
  const auto xOpen = [&](int i, int j) { return active_[static_cast<std::size_t>(i + (nx_ + 1) * j)] != 0 ? 1.0 : 0.0; };
  const auto yOpen = [&](int i, int j) { return active_[xFaces + static_cast<std::size_t>(i + nx_ * j)] != 0 ? 1.0 : 0.0; };
  const double inv2 = 1.0 / (grid_.dx * grid_.dx);
  columnNorms_.resize(static_cast<Eigen::Index>(cells + static_cast<std::size_t>((nx_ + 1) * (ny_ + 1))));
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i)
      columnNorms_[i + nx_ * j] = inv2 * (xOpen(i, j) + xOpen(i + 1, j) + yOpen(i, j) + yOpen(i, j + 1));
  for (int j = 0; j <= ny_; ++j)
    for (int i = 0; i <= nx_; ++i)
      columnNorms_[static_cast<Eigen::Index>(cells) + i + (nx_ + 1) * j] =
          inv2 * ((j > 0 ? xOpen(i, j - 1) : 0.0) + (j < ny_ ? xOpen(i, j) : 0.0) + (i > 0 ? yOpen(i - 1, j) : 0.0) +
                  (i < nx_ ? yOpen(i, j) : 0.0));
}

FrictionResult StressGrid::friction(const Eigen::VectorXd& momentum, double dt, const StressLaws& laws,
                                    const numerics::BoundQpSettings& settings, Eigen::VectorXd& change) {
  if (momentum.size() != static_cast<Eigen::Index>(active_.size()))
    throw std::invalid_argument("stress grid: one momentum per face expected");
  if (!(dt > 0.0)) throw std::invalid_argument("stress grid: the step must be > 0");
  const Eigen::Index unknowns = columnNorms_.size();
  // The bounds: each cell's density for s_d, the mean of the open cells around a corner for s_o.
  upper_.resize(unknowns);
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) upper_[i + nx_ * j] = frictionBound(density_(IVec<2>(i, j)), laws);
  const Eigen::Index cells = nx_ * ny_;
  for (int j = 0; j <= ny_; ++j)
    for (int i = 0; i <= nx_; ++i) {
      double sum = 0.0;
      int count = 0;
      for (int dj = -1; dj <= 0; ++dj)
        for (int di = -1; di <= 0; ++di) {
          const IVec<2> c(i + di, j + dj);
          if (!density_.inside(c) || covered_(c) != 0.0f) continue;
          sum += density_(c);
          ++count;
        }
      upper_[cells + i + (nx_ + 1) * j] = count > 0 ? frictionBound(sum / count, laws) : 0.0;
    }
  lower_ = -upper_;
  // 1/2 s^T A s - b^T s with A = dt^2 / rho_y D^T D and b = -dt / rho_y D^T m*: E(s) - E(0).
  const double scale = dt * dt / laws.yield;
  // Unknowns no open face sees (inside walls) take the largest real diagonal.
  diagonal_ = scale * columnNorms_;
  const double largest = numerics::setDecoupledDiagonals(
      std::span<double>(diagonal_.data(), static_cast<std::size_t>(diagonal_.size())),
      [&](std::size_t k) { return !(columnNorms_[static_cast<Eigen::Index>(k)] > 0.0); });
  const double h = grid_.dx;
  const FrictionOperator op(*this, scale, diagonal_, columnNorms_, std::max(8.0 * scale / (h * h), largest), faces_);
  divergenceTranspose(momentum, rhs_);
  rhs_ *= -dt / laws.yield;
  if (stress_.size() != unknowns) stress_ = Eigen::VectorXd::Zero(unknowns);
  stress_ = stress_.cwiseMax(lower_).cwiseMin(upper_);
  FrictionResult result;
  result.qp = solver_.solve(op, rhs_, lower_, upper_, stress_, settings);
  divergence(stress_, change);
  change *= dt;
  result.energyBefore = momentum.squaredNorm() / (2.0 * laws.yield);
  result.energyAfter = (momentum + change).squaredNorm() / (2.0 * laws.yield);
  return result;
}

double StressGrid::energy(const Eigen::VectorXd& momentum, const Eigen::VectorXd& stress, double dt,
                          const StressLaws& laws) const {
  Eigen::VectorXd change;
  divergence(stress, change);
  return (momentum + dt * change).squaredNorm() / (2.0 * laws.yield);
}

}  // namespace msim::crowd::stress
