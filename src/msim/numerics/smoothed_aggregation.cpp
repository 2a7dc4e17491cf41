#include "msim/numerics/smoothed_aggregation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>


namespace msim::numerics {

namespace {

using Matrix = SmoothedAggregation::Matrix;

// A direct solve stops paying off above this many unknowns; a coarsest level that large (coarsening
// stalled) is smoothed instead.
constexpr Eigen::Index kDirectLimit = 20000;
constexpr int kCoarsestSweeps = 8;

// The block Frobenius norms ||A_ij||^2 of each node's row, as node-level CSR.
struct NodeGraph {
  std::vector<int> start, node;
  std::vector<double> norm2;
  std::vector<double> diagonal2;  // ||A_ii||^2
};

NodeGraph nodeGraph(const Matrix& A, int b) {
  const int n = static_cast<int>(A.rows() / b);
  NodeGraph g;
  g.start.assign(static_cast<std::size_t>(n) + 1, 0);
  g.diagonal2.assign(static_cast<std::size_t>(n), 0.0);
  std::vector<int> slot(static_cast<std::size_t>(n), -1);  // position of node j in the current row's list
  for (int i = 0; i < n; ++i) {
    const std::size_t rowStart = g.node.size();
    for (int k = 0; k < b; ++k)
      for (Matrix::InnerIterator it(A, i * b + k); it; ++it) {
        const int j = static_cast<int>(it.col() / b);
        if (slot[static_cast<std::size_t>(j)] < 0) {
          slot[static_cast<std::size_t>(j)] = static_cast<int>(g.node.size());
          g.node.push_back(j);
          g.norm2.push_back(0.0);
        }
        g.norm2[static_cast<std::size_t>(slot[static_cast<std::size_t>(j)])] += it.value() * it.value();
      }
    for (std::size_t e = rowStart; e < g.node.size(); ++e) {
      if (g.node[e] == i) g.diagonal2[static_cast<std::size_t>(i)] = g.norm2[e];
      slot[static_cast<std::size_t>(g.node[e])] = -1;
    }
    g.start[static_cast<std::size_t>(i) + 1] = static_cast<int>(g.node.size());
  }
  return g;
}

// Aggregates of strongly connected nodes (Vanek et al. 1996, sec. 4.1): first whole neighbourhoods
// of nodes none of whose strong neighbours is taken, then the rest join the aggregate they are most
// strongly connected to, and what remains groups with its free neighbours. -1: an isolated node.
std::vector<int> aggregate(const NodeGraph& g, double theta, int& count) {
  const std::size_t n = g.diagonal2.size();
  std::vector<int> strongStart(n + 1, 0), strong;
  std::vector<double> strength;
  for (std::size_t i = 0; i < n; ++i) {
    for (int e = g.start[i]; e < g.start[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(g.node[static_cast<std::size_t>(e)]);
      const double s2 = g.norm2[static_cast<std::size_t>(e)];
      if (j != i && s2 >= theta * theta * std::sqrt(g.diagonal2[i] * g.diagonal2[j])) {
        strong.push_back(static_cast<int>(j));
        strength.push_back(s2 / std::sqrt(g.diagonal2[i] * g.diagonal2[j]));
      }
    }
    strongStart[i + 1] = static_cast<int>(strong.size());
  }
  constexpr int kFree = -2;
  std::vector<int> label(n, kFree);
  count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (strongStart[i] == strongStart[i + 1]) label[i] = -1;  // isolated
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (label[i] != kFree) continue;
    bool allFree = true;
    for (int e = strongStart[i]; e < strongStart[i + 1] && allFree; ++e)
      allFree = label[static_cast<std::size_t>(strong[static_cast<std::size_t>(e)])] == kFree;
    if (!allFree) continue;
    label[i] = count;
    for (int e = strongStart[i]; e < strongStart[i + 1]; ++e) label[static_cast<std::size_t>(strong[static_cast<std::size_t>(e)])] = count;
    ++count;
  }
  const std::vector<int> first = label;
  for (std::size_t i = 0; i < n; ++i) {
    if (label[i] != kFree) continue;
    double best = -1.0;
    for (int e = strongStart[i]; e < strongStart[i + 1]; ++e) {
      const int a = first[static_cast<std::size_t>(strong[static_cast<std::size_t>(e)])];
      if (a >= 0 && strength[static_cast<std::size_t>(e)] > best) {
        best = strength[static_cast<std::size_t>(e)];
        label[i] = a;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (label[i] != kFree) continue;
    label[i] = count;
    for (int e = strongStart[i]; e < strongStart[i + 1]; ++e) {
      const auto j = static_cast<std::size_t>(strong[static_cast<std::size_t>(e)]);
      if (label[j] == kFree) label[j] = count;
    }
    ++count;
  }
  return label;
}

// rho(D^-1 A) by power iteration from a fixed start (deterministic), rounded up a little: the
// iteration approaches the largest eigenvalue from below.
double spectralRadius(const Matrix& A, const BlockJacobi& jacobi) {
  Eigen::VectorXd x(A.rows()), y, z;
  for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = 1.0 + 0.5 * std::sin(1.7 * static_cast<double>(i));
  double rho = 0.0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    x /= std::sqrt(parallelDot(x, x));
    parallelMultiply(A, x, y);
    jacobi.apply(y, z);
    rho = std::sqrt(parallelDot(z, z));
    x = z;
  }
  return 1.05 * rho;
}

// The tentative prolongator (Vanek et al. 1996, sec. 3): for each aggregate, the rows of the
// near-null space `modes` on its nodes, orthonormalised (modified Gram-Schmidt, twice, which keeps
// orthogonality to rounding); its k columns are the aggregate's k coarse unknowns, and the
// coefficients R (B = Q R) the coarse level's near-null space. A mode that is dependent on the
// aggregate (a rotation about the line of two nodes) leaves a zero column: that coarse unknown is
// left out (withUnitDiagonalWhereEmpty).
Matrix tentativeProlongator(const std::vector<int>& label, int count, int b, const Eigen::MatrixXd& modes,
                            Eigen::MatrixXd& coarseModes) {
  const int k = static_cast<int>(modes.cols());
  std::vector<std::vector<int>> members(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < label.size(); ++i)
    if (label[i] >= 0) members[static_cast<std::size_t>(label[i])].push_back(static_cast<int>(i));
  coarseModes = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(count) * k, k);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(modes.rows()) * static_cast<std::size_t>(k));
  std::vector<double> q;  // the aggregate's rows x k, column-major
  for (int a = 0; a < count; ++a) {
    const std::vector<int>& nodes = members[static_cast<std::size_t>(a)];
    const std::size_t rows = nodes.size() * static_cast<std::size_t>(b);
    q.assign(rows * static_cast<std::size_t>(k), 0.0);
    for (std::size_t m = 0; m < nodes.size(); ++m)
      for (int l = 0; l < b; ++l)
        for (int c = 0; c < k; ++c) q[static_cast<std::size_t>(c) * rows + m * b + l] = modes(static_cast<Eigen::Index>(nodes[m]) * b + l, c);
    const auto column = [&](int c) { return q.data() + static_cast<std::size_t>(c) * rows; };
    const auto dot = [rows](const double* x, const double* y) {
      double sum = 0.0;
      for (std::size_t r = 0; r < rows; ++r) sum += x[r] * y[r];
      return sum;
    };
    for (int c = 0; c < k; ++c) {
      double* v = column(c);
      const double original = std::sqrt(dot(v, v));
      for (int pass = 0; pass < 2; ++pass)
        for (int j = 0; j < c; ++j) {
          const double r = dot(column(j), v);
          for (std::size_t row = 0; row < rows; ++row) v[row] -= r * column(j)[row];
          coarseModes(static_cast<Eigen::Index>(a) * k + j, c) += r;
        }
      const double norm = std::sqrt(dot(v, v));
      if (!(norm > 1e-10 * original)) {
        std::fill(v, v + rows, 0.0);
        continue;
      }
      for (std::size_t row = 0; row < rows; ++row) v[row] /= norm;
      coarseModes(static_cast<Eigen::Index>(a) * k + c, c) = norm;
    }
    for (std::size_t m = 0; m < nodes.size(); ++m)
      for (int l = 0; l < b; ++l)
        for (int c = 0; c < k; ++c) {
          const double value = column(c)[m * b + l];
          if (value != 0.0) entries.emplace_back(static_cast<Eigen::Index>(nodes[m]) * b + l, static_cast<Eigen::Index>(a) * k + c, value);
        }
  }
  Matrix tentative(modes.rows(), static_cast<Eigen::Index>(count) * k);
  tentative.setFromTriplets(entries.begin(), entries.end());
  return tentative;
}

// The coarse matrix with 1 on the diagonal of the unknowns no fine one reaches (a zero column of
// the prolongator): they decouple, with a zero right-hand side, instead of making their block
// singular.
Matrix withUnitDiagonalWhereEmpty(Matrix coarse) {
  coarse.makeCompressed();
  std::vector<Eigen::Triplet<double>> unit;
  for (Eigen::Index row = 0; row < coarse.rows(); ++row) {
    double diagonal = 0.0, largest = 0.0;
    for (Matrix::InnerIterator it(coarse, row); it; ++it) {
      largest = std::max(largest, std::abs(it.value()));
      if (it.col() == row) diagonal = it.value();
    }
    if (!(diagonal > 0.0) && largest == 0.0) unit.emplace_back(row, row, 1.0);
  }
  if (unit.empty()) return coarse;
  Matrix identity(coarse.rows(), coarse.cols());
  identity.setFromTriplets(unit.begin(), unit.end());
  Matrix fixed = coarse + identity;
  fixed.makeCompressed();
  return fixed;
}

}  // namespace

SmoothedAggregation::SmoothedAggregation(const AggregationSettings& settings) : settings_(settings) {
  if (settings.blockSize < 1 || settings.blockSize > 6)
    throw std::invalid_argument("smoothed aggregation: the block size must be 1-6");
}

void SmoothedAggregation::setup(const Matrix& A, const Eigen::MatrixXd& nearNullSpace) {
  const int b = settings_.blockSize;
  if (A.rows() != A.cols() || A.rows() == 0 || A.rows() % b != 0)
    throw std::invalid_argument("smoothed aggregation: the matrix must be square, non-empty and of whole blocks");
  if (nearNullSpace.size() > 0 && (nearNullSpace.rows() != A.rows() || nearNullSpace.cols() < 1 || nearNullSpace.cols() > 6))
    throw std::invalid_argument("smoothed aggregation: the near-null space needs a row per unknown and 1-6 columns");
  // Without one given, the near-null space is the b translations: the identity on every node.
  Eigen::MatrixXd modes = nearNullSpace;
  if (modes.size() == 0) {
    modes = Eigen::MatrixXd::Zero(A.rows(), b);
    for (Eigen::Index row = 0; row < A.rows(); ++row) modes(row, row % b) = 1.0;
  }
  const int k = static_cast<int>(modes.cols());  // unknowns per coarse node
  levels_.clear();
  levels_.emplace_back();
  levels_.back().A = A;
  levels_.back().A.makeCompressed();
  levels_.back().blockSize = b;
  for (;;) {
    Level& fine = levels_.back();
    const int fb = fine.blockSize;
    fine.jacobi.setup(fine.A, fb);
    fine.weight = 4.0 / (3.0 * spectralRadius(fine.A, fine.jacobi));
    const Eigen::Index nodes = fine.A.rows() / fb;
    if (nodes <= settings_.coarsestNodes || static_cast<int>(levels_.size()) >= settings_.maxLevels) break;
    int count = 0;
    const std::vector<int> label = aggregate(nodeGraph(fine.A, fb), settings_.strengthThreshold, count);
    if (count == 0 || count * k > 0.85 * static_cast<double>(fine.A.rows())) break;  // coarsening has stalled
    Eigen::MatrixXd coarseModes;
    const Matrix tentative = tentativeProlongator(label, count, fb, modes, coarseModes);
    const Matrix inverseDiagonal = fine.jacobi.inverseMatrix();
    const Matrix smoothing = parallelProduct(inverseDiagonal, parallelProduct(fine.A, tentative));
    fine.P = tentative - fine.weight * smoothing;
    fine.P.makeCompressed();
    fine.R = fine.P.transpose();
    Matrix coarse = parallelProduct(fine.R, parallelProduct(fine.A, fine.P));
    levels_.emplace_back();
    levels_.back().A = withUnitDiagonalWhereEmpty(coarse);
    levels_.back().blockSize = k;
    modes = std::move(coarseModes);
  }
  Level& last = levels_.back();
  coarsest_.reset();
  if (last.A.rows() <= kDirectLimit) {
    coarsest_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>>(Eigen::SparseMatrix<double>(last.A));
    if (coarsest_->info() != Eigen::Success)
      throw std::invalid_argument("smoothed aggregation: the coarsest matrix is not positive definite");
  }
  for (Level& level : levels_) {
    level.x.resize(level.A.rows());
    level.b.resize(level.A.rows());
    level.residual.resize(level.A.rows());
    level.correction.resize(level.A.rows());
  }
}

double SmoothedAggregation::operatorComplexity() const {
  if (levels_.empty()) return 0.0;
  double total = 0.0;
  for (const Level& level : levels_) total += static_cast<double>(level.A.nonZeros());
  return total / static_cast<double>(levels_.front().A.nonZeros());
}

void SmoothedAggregation::smooth(const Level& level) const {
  parallelMultiply(level.A, level.x, level.residual);
  level.residual = level.b - level.residual;
  level.jacobi.apply(level.residual, level.correction);
  level.x += level.weight * level.correction;
}

void SmoothedAggregation::cycle(std::size_t index) const {
  const Level& level = levels_[index];
  const bool coarsest = index + 1 == levels_.size();
  if (coarsest && coarsest_) {
    level.x = coarsest_->solve(level.b);
    return;
  }
  const int sweeps = coarsest ? kCoarsestSweeps : std::max(1, settings_.smoothingSweeps);
  level.jacobi.apply(level.b, level.correction);  // the first sweep from x = 0 needs no product
  level.x = level.weight * level.correction;
  for (int s = 1; s < sweeps; ++s) smooth(level);
  if (coarsest) return;
  const Level& coarse = levels_[index + 1];
  parallelMultiply(level.A, level.x, level.residual);
  level.residual = level.b - level.residual;
  parallelMultiply(level.R, level.residual, coarse.b);
  cycle(index + 1);
  parallelMultiply(level.P, coarse.x, level.residual);
  level.x += level.residual;
  for (int s = 0; s < sweeps; ++s) smooth(level);
}

Eigen::MatrixXd rigidModes(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& center) {
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(3 * points.size()), 6);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = points[i] - center;
    const auto row = static_cast<Eigen::Index>(3 * i);
    for (int a = 0; a < 3; ++a) modes(row + a, a) = 1.0;
    // omega x p for omega along x, y and z
    modes(row + 1, 3) = -p.z();
    modes(row + 2, 3) = p.y();
    modes(row + 0, 4) = p.z();
    modes(row + 2, 4) = -p.x();
    modes(row + 0, 5) = -p.y();
    modes(row + 1, 5) = p.x();
  }
  return modes;
}

void SmoothedAggregation::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  if (levels_.empty()) throw std::logic_error("smoothed aggregation: apply before setup");
  levels_.front().b = r;
  cycle(0);
  z = levels_.front().x;
}

}  // namespace msim::numerics
