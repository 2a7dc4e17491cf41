// Navigation field: blocked-cell mask, goal seeding, fast marching (Sethian 1996) and queries.
#include "msim/crowd/navigation_field.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"

namespace msim::crowd {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();

struct Box {
  Vec2 lo, hi;
};

Box boundsOf(const Polygon& p) {
  Box b;
  bounds(p, b.lo, b.hi);
  return b;
}

std::string str(const Vec2& v) { return fmt::format("({:g}, {:g})", v.x(), v.y()); }

// Cells fixed before marching with their exact value: distance to the goal point, or to the goal
// region (0 inside). Exact seeds remove the O(h) offset a phi = 0 seed band would add.
using Seeds = std::vector<std::pair<std::size_t, double>>;

// Fast marching from the seeds over unblocked cells; returns phi (+inf where unreachable).
// Second-order upwind differences where two known cells line up on an axis, first order
// otherwise, and a one-axis update when the two-axis quadratic has no causal root.
std::vector<float> march(const IVec2& n, double h, const std::vector<std::uint8_t>& blocked, const Seeds& seeds) {
  const std::size_t count = blocked.size();
  std::vector<double> t(count, kInf);
  enum : std::uint8_t { Far, Trial, Known, Fixed };
  std::vector<std::uint8_t> state(count, Far);
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
  for (const auto& [cell, value] : seeds) {
    if (value < t[cell]) t[cell] = value;
    state[cell] = Fixed;
  }
  for (const auto& [cell, value] : seeds) heap.emplace(t[cell], cell);

  const auto known = [&](int i, int j) {
    if (i < 0 || j < 0 || i >= n[0] || j >= n[1]) return false;
    const std::uint8_t s = state[static_cast<std::size_t>(j) * n[0] + i];
    return s == Known || s == Fixed;
  };
  const auto value = [&](int i, int j) { return t[static_cast<std::size_t>(j) * n[0] + i]; };

  // Upwind term (a, t) of one axis: a (T - t)^2 is that axis' share of h^2 |grad T|^2.
  struct Term {
    double a1, t1;  // first order
    double a2, t2;  // second order where available (else equal to first order)
  };
  const auto axisTerm = [&](int i, int j, int di, int dj, Term& term) {
    bool found = false;
    for (int s : {-1, 1}) {
      const int i1 = i + s * di, j1 = j + s * dj;
      if (!known(i1, j1)) continue;
      const double t1 = value(i1, j1);
      if (found && t1 >= term.t1) continue;
      found = true;
      term = {1.0, t1, 1.0, t1};
      const int i2 = i1 + s * di, j2 = j1 + s * dj;
      if (known(i2, j2) && value(i2, j2) <= t1) term.a2 = 2.25, term.t2 = (4.0 * t1 - value(i2, j2)) / 3.0;
    }
    return found;
  };
  // Largest root of sum a_k (T - t_k)^2 = h^2 if it is causal (T >= every t_k).
  const auto solve = [&](const Term* terms, int m, bool second, double& out) {
    double a = 0, b = 0, c = -h * h, tmax = -kInf;
    for (int k = 0; k < m; ++k) {
      const double ak = second ? terms[k].a2 : terms[k].a1, tk = second ? terms[k].t2 : terms[k].t1;
      a += ak, b -= 2 * ak * tk, c += ak * tk * tk;
      tmax = std::max(tmax, tk);
    }
    const double disc = b * b - 4 * a * c;
    if (disc < 0) return false;
    out = (-b + std::sqrt(disc)) / (2 * a);
    return out >= tmax;
  };
  const auto update = [&](int i, int j) {
    Term terms[2];
    int m = 0;
    if (axisTerm(i, j, 1, 0, terms[m])) ++m;
    if (axisTerm(i, j, 0, 1, terms[m])) ++m;
    if (m == 0) return kInf;
    double out;
    if (solve(terms, m, true, out) || solve(terms, m, false, out)) return out;
    double best = kInf;
    for (int k = 0; k < m; ++k) best = std::min(best, terms[k].t1 + h);
    return best;
  };

  while (!heap.empty()) {
    const auto [tv, cell] = heap.top();
    heap.pop();
    if (tv > t[cell] || state[cell] == Known) continue;
    if (state[cell] != Fixed) state[cell] = Known;
    const int i = static_cast<int>(cell % n[0]), j = static_cast<int>(cell / n[0]);
    const int ni[4] = {i - 1, i + 1, i, i}, nj[4] = {j, j, j - 1, j + 1};
    for (int k = 0; k < 4; ++k) {
      if (ni[k] < 0 || nj[k] < 0 || ni[k] >= n[0] || nj[k] >= n[1]) continue;
      const std::size_t nb = static_cast<std::size_t>(nj[k]) * n[0] + ni[k];
      if (blocked[nb] || state[nb] == Known || state[nb] == Fixed) continue;
      const double candidate = update(ni[k], nj[k]);
      if (candidate < t[nb]) {
        t[nb] = candidate;
        state[nb] = Trial;
        heap.emplace(candidate, nb);
      }
    }
  }
  return std::vector<float>(t.begin(), t.end());
}

}  // namespace

NavigationField::NavigationField(std::vector<Goal> goals, std::vector<Polygon> obstacles,
                                 const NavigationFieldOptions& options)
    : goals_(std::move(goals)), options_(options) {
  const double h = options_.cellSize;
  if (!(h > 0) || !std::isfinite(h)) throw InputError(fmt::format("navigation field: cell size must be > 0, got {:g}", h));
  if (!(options_.clearance >= 0)) throw InputError(fmt::format("navigation field: clearance must be >= 0, got {:g}", options_.clearance));
  if (!options_.lo.allFinite() || !options_.hi.allFinite() || !((options_.hi - options_.lo).minCoeff() >= 2 * h))
    throw InputError(fmt::format("navigation field: domain {} .. {} must span at least two {:g} m cells per axis",
                                 str(options_.lo), str(options_.hi), h));
  for (int d = 0; d < 2; ++d) n_[d] = static_cast<int>(std::ceil((options_.hi[d] - options_.lo[d]) / h - 1e-9));
  for (std::size_t k = 0; k < obstacles.size(); ++k) validateSimple(obstacles[k], fmt::format("obstacles[{}]", k));

  // Blocked mask: centre within the (effective) clearance of an obstacle. Rows in parallel, each
  // visiting only the obstacles whose inflated bounds reach it.
  const double reach = std::max(options_.clearance, 0.5 * h);
  std::vector<Box> boxes;
  for (const Polygon& p : obstacles) boxes.push_back(boundsOf(p));
  blocked_.assign(static_cast<std::size_t>(n_[0]) * n_[1], 0);
  parallelFor(0, static_cast<std::size_t>(n_[1]), [&](std::size_t row) {
    const int j = static_cast<int>(row);
    const double y = centre(0, j).y();
    for (std::size_t k = 0; k < obstacles.size(); ++k) {
      if (y < boxes[k].lo.y() - reach || y > boxes[k].hi.y() + reach) continue;
      const int i0 = std::max(0, static_cast<int>(std::floor((boxes[k].lo.x() - reach - options_.lo.x()) / h - 0.5)));
      const int i1 = std::min(n_[0] - 1, static_cast<int>(std::ceil((boxes[k].hi.x() + reach - options_.lo.x()) / h - 0.5)));
      for (int i = i0; i <= i1; ++i) {
        std::uint8_t& b = blocked_[index(i, j)];
        if (!b && signedDistance(obstacles[k], centre(i, j)) <= reach) b = 1;
      }
    }
  }, 1);

  // Goal validation and seeds (serial: cheap, and errors come out in goal order).
  std::vector<Seeds> seeds(goals_.size());
  const auto inDomain = [&](const Vec2& x) { return (x.array() >= options_.lo.array()).all() && (x.array() <= options_.hi.array()).all(); };
  const auto cellRange = [&](const Vec2& lo, const Vec2& hi, IVec2& c0, IVec2& c1) {
    for (int d = 0; d < 2; ++d) {
      c0[d] = std::max(0, static_cast<int>(std::floor((lo[d] - options_.lo[d]) / h - 0.5)));
      c1[d] = std::min(n_[d] - 1, static_cast<int>(std::ceil((hi[d] - options_.lo[d]) / h - 0.5)));
    }
  };
  for (std::size_t g = 0; g < goals_.size(); ++g) {
    const Goal& goal = goals_[g];
    IVec2 c0, c1;
    if (goal.kind == Goal::Kind::Point) {
      if (!goal.point.allFinite() || !inDomain(goal.point))
        throw InputError(fmt::format("goals[{}]: point {} lies outside the planning domain {} .. {}", g, str(goal.point),
                                     str(options_.lo), str(options_.hi)));
      for (std::size_t k = 0; k < obstacles.size(); ++k)
        if (contains(obstacles[k], goal.point))
          throw InputError(fmt::format("goals[{}]: point {} lies inside obstacles[{}]", g, str(goal.point), k));
      // Seed the cells around the point; if the clearance band covers them, any walkable cell
      // within the arrival radius will do (the agent arrives there anyway).
      for (double radius : {1.5 * h, goal.arrivalRadius + h}) {
        cellRange(goal.point - Vec2::Constant(radius), goal.point + Vec2::Constant(radius), c0, c1);
        for (int j = c0[1]; j <= c1[1]; ++j)
          for (int i = c0[0]; i <= c1[0]; ++i) {
            const double d = (centre(i, j) - goal.point).norm();
            if (!blocked_[index(i, j)] && d <= radius) seeds[g].emplace_back(index(i, j), d);
          }
        if (!seeds[g].empty()) break;
      }
      if (seeds[g].empty())
        throw InputError(fmt::format("goals[{}]: no walkable cell within the arrival radius {:g} m of point {} (closer than "
                                     "the clearance {:g} m to an obstacle?)", g, goal.arrivalRadius, str(goal.point), reach));
    } else {
      // Every region of a set seeds the same front: the field's distance is to the nearest one.
      for (std::size_t m = 0; m < goal.regions.size(); ++m) {
        const Polygon& region = goal.regions[m];
        // The scene's names: the first region is the goal's shape, the others its more_shapes.
        const std::string key = m == 0 ? fmt::format("goals[{}].region", g) : fmt::format("goals[{}].more_shapes[{}]", g, m - 1);
        validateSimple(region, key);
        const Box b = boundsOf(region);
        cellRange(b.lo - Vec2::Constant(1.5 * h), b.hi + Vec2::Constant(1.5 * h), c0, c1);
        bool inside = false;
        for (int j = c0[1]; j <= c1[1]; ++j)
          for (int i = c0[0]; i <= c1[0]; ++i) {
            if (blocked_[index(i, j)]) continue;
            const double d = std::max(0.0, signedDistance(region, centre(i, j)));
            inside |= d == 0;
            if (d <= 1.5 * h) seeds[g].emplace_back(index(i, j), d);
          }
        if (!inside)
          throw InputError(fmt::format("{}: no walkable cell centre inside the region (outside the domain, inside an "
                                       "obstacle, or smaller than a {:g} m cell?)", key, h));
      }
    }
  }

  phi_.resize(goals_.size());
  tbb::parallel_for(std::size_t(0), goals_.size(), [&](std::size_t g) { phi_[g] = march(n_, h, blocked_, seeds[g]); });
}

Vec2 NavigationField::centre(int i, int j) const {
  return options_.lo + options_.cellSize * Vec2(i + 0.5, j + 0.5);
}

Vec2 NavigationField::cellDirection(std::size_t goal, int i, int j) const {
  const float p = phi(goal, i, j);
  Vec2 d = Vec2::Zero();
  // Central difference where phi is monotone across the cell (second order, both neighbours
  // walkable); one-sided towards the lower neighbour at kinks (ridges where fronts meet) and
  // next to blocked cells.
  const auto axis = [&](int dim, float lower, float upper) {
    if (std::isfinite(lower) && std::isfinite(upper) && std::min(lower, upper) < p && p < std::max(lower, upper)) {
      d[dim] = 0.5 * (lower - upper);
      return;
    }
    const float m = std::min(lower, upper);
    if (m < p) d[dim] = (upper < lower ? 1.0 : -1.0) * (p - m);
  };
  axis(0, i > 0 ? phi(goal, i - 1, j) : kInfF, i + 1 < n_[0] ? phi(goal, i + 1, j) : kInfF);
  axis(1, j > 0 ? phi(goal, i, j - 1) : kInfF, j + 1 < n_[1] ? phi(goal, i, j + 1) : kInfF);
  const double norm = d.norm();
  return norm > 0 ? Vec2(d / norm) : Vec2::Zero();
}

bool NavigationField::nearestFinite(std::size_t goal, const Vec2& position, int& ci, int& cj) const {
  const double h = options_.cellSize;
  const int r = static_cast<int>(std::ceil(std::max(options_.clearance, 0.5 * h) / h)) + 2;
  const int i0 = static_cast<int>(std::floor((position.x() - options_.lo.x()) / h));
  const int j0 = static_cast<int>(std::floor((position.y() - options_.lo.y()) / h));
  double best = kInf;
  for (int j = std::max(0, j0 - r); j <= std::min(n_[1] - 1, j0 + r); ++j)
    for (int i = std::max(0, i0 - r); i <= std::min(n_[0] - 1, i0 + r); ++i) {
      if (!std::isfinite(phi(goal, i, j))) continue;
      const double d = (centre(i, j) - position).squaredNorm();
      if (d < best) best = d, ci = i, cj = j;
    }
  return best < kInf;
}

namespace {

// Bilinear stencil over cell centres: corner (i0 + di, j0 + dj) has weight w[dj][di].
struct Stencil {
  int i0, j0;
  double w[2][2];
};

Stencil stencil(const Vec2& lo, double h, const IVec2& n, const Vec2& x) {
  Stencil s;
  double t[2];
  int c[2];
  for (int d = 0; d < 2; ++d) {
    const double f = (x[d] - lo[d]) / h - 0.5;
    c[d] = std::clamp(static_cast<int>(std::floor(f)), 0, n[d] - 2);
    t[d] = std::clamp(f - c[d], 0.0, 1.0);
  }
  s.i0 = c[0], s.j0 = c[1];
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) s.w[dj][di] = (di ? t[0] : 1 - t[0]) * (dj ? t[1] : 1 - t[1]);
  return s;
}

}  // namespace

double NavigationField::distance(std::size_t goal, const Vec2& position) const {
  const Goal& g = goals_.at(goal);
  if (g.kind == Goal::Kind::Region && g.inside(position)) return 0.0;
  const Stencil s = stencil(options_.lo, options_.cellSize, n_, position);
  double sum = 0, weight = 0;
  bool walkable = false;
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const float p = phi(goal, s.i0 + di, s.j0 + dj);
      walkable |= !blocked(s.i0 + di, s.j0 + dj);
      if (std::isfinite(p) && s.w[dj][di] > 0) sum += s.w[dj][di] * p, weight += s.w[dj][di];
    }
  if (weight > 0) return sum / weight;
  // A walkable stencil without finite phi is cut off from the goal; an all-blocked one means the
  // agent stands in the clearance band: measure from the nearest reachable cell.
  int ci, cj;
  if (walkable || !nearestFinite(goal, position, ci, cj)) return kInf;
  return phi(goal, ci, cj) + (centre(ci, cj) - position).norm();
}

bool NavigationField::reachable(std::size_t goal, const Vec2& position) const {
  return std::isfinite(distance(goal, position));
}

Vec2 NavigationField::direction(std::size_t goal, const Vec2& position) const {
  const Goal& g = goals_.at(goal);
  if (g.reached(position)) return Vec2::Zero();
  // Within two cells of a point goal the upwind differences resolve the point poorly; the
  // straight line is the geodesic there.
  if (g.kind == Goal::Kind::Point && (g.point - position).norm() <= 2 * options_.cellSize)
    return (g.point - position).normalized();
  // Bilinear blend of per-cell descent directions over the finite cells only: each of them
  // points to lower, hence walkable, neighbours, so the blend never heads into a blocked cell.
  const Stencil s = stencil(options_.lo, options_.cellSize, n_, position);
  Vec2 sum = Vec2::Zero();
  bool walkable = false, finite = false;
  float lowest = kInfF;
  Vec2 lowestDir = Vec2::Zero();
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di) {
      const int i = s.i0 + di, j = s.j0 + dj;
      const float p = phi(goal, i, j);
      walkable |= !blocked(i, j);
      if (!std::isfinite(p)) continue;
      finite = true;
      const Vec2 d = cellDirection(goal, i, j);
      sum += s.w[dj][di] * d;
      if (p < lowest) lowest = p, lowestDir = d;
    }
  if (finite) {
    // Opposite cell directions cancel on a ridge (equal paths round both sides of an obstacle):
    // follow the lowest cell's direction then.
    const double norm = sum.norm();
    return norm > 1e-6 ? Vec2(sum / norm) : lowestDir;
  }
  int ci, cj;
  if (walkable || !nearestFinite(goal, position, ci, cj)) return Vec2::Zero();
  // Inside the clearance band: step out towards the nearest reachable cell.
  const Vec2 out = centre(ci, cj) - position;
  return out.norm() > 0 ? Vec2(out.normalized()) : cellDirection(goal, ci, cj);
}

}  // namespace msim::crowd
