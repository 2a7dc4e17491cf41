// Selle ch. 2.8, Figures 2.6-2.8: Zalesak's slotted disc (centre (50,75), radius 15, slot 5 x 25
// cut up from the bottom of the disc) as a signed distance on [0,100]^2, rotated once (t = 628)
// by V = pi/314 (50 - y, x - 50), with no reinitialisation.
//  * "Grid size 101^2": 101 nodes per axis on [0,100]^2 (dx = 1); the order formula
//    log2(e(i,j) / e'(2i-1, 2j-1)) needs nodes that coincide between grids.
//  * "Error": mean |phi - phi_0| over those nodes; "Order": mean over the coincident nodes of
//    log2 of the pointwise error ratio (ch. 2.8), skipping nodes with a zero error (the rotation
//    centre keeps its value exactly under upwinding).
//  * Semi-Lagrangian blocks trace Selle's straight ray X - dt V(X) (ch. 2.3).
//  * dt = CFL dx / max(|u| + |v|) over [0,100]^2; the last step is shortened to land on t = 628.
//  * No limiter: Tables 2.2/2.3, run with the same schemes, are only reproduced unlimited.
//  * Boundary data: the nodes outside [0,100]^2 hold the exact solution, refreshed after every
//    step. Which inflow data Selle used is not written; this is the reading under which his
//    first-order columns come out (zero-gradient data at the walls gives 2x-15x his errors;
//    padding the grid and advecting the padding gives first-order errors 25-40 % too large,
//    because the corner data then carry the diffusion of their trip outside).
// docs/advection.md lists every entry, ours and Selle's, and why some are not checked.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "../sanitizer_build.hpp"
#include "msim/numerics/advection/advector.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr double kOmega = std::numbers::pi / 314.0;
constexpr double kOneTurn = 2.0 * std::numbers::pi / kOmega;  // one turn, t = 628
// Nodes outside [0,100]^2 on each side. A BFECC step reads at most 3 building blocks x 2 nodes
// outwards (the foot moves < 2 dx even at CFL 1.75), so the values the clamped outer edge spoils
// within a step never reach [0,100]^2 (results are identical with 16).
constexpr int kGhost = 8;

double boxDistance(const Vec2& p, const Vec2& centre, const Vec2& half) {
  const Vec2 d = (p - centre).cwiseAbs() - half;
  return d.cwiseMax(0.0).norm() + std::min(std::max(d.x(), d.y()), 0.0);
}

// Disc minus slot, as the usual CSG combination of the two exact distances.
double slottedDisc(const Vec2& p) {
  const double disc = (p - Vec2(50, 75)).norm() - 15.0;
  const double slot = boxDistance(p, Vec2(50, 72.5), Vec2(2.5, 12.5));
  return std::max(disc, -slot);
}

// The exact solution at time t: the initial data at the point the rotation carried here.
double exact(const Vec2& p, double t) {
  const double c = std::cos(kOmega * t), s = std::sin(kOmega * t);
  const Vec2 r = p - Vec2(50, 50);
  return slottedDisc(Vec2(50 + c * r.x() + s * r.y(), 50 - s * r.x() + c * r.y()));
}

// |phi - phi_0| at the nodes of [0,100]^2 (row-major, `nodes` per axis) after one turn.
std::vector<double> nodeErrors(int nodes, BuildingBlock block, AdvectionScheme scheme, double cfl) {
  const double dx = 100.0 / (nodes - 1);
  const int n = nodes + 2 * kGhost;
  // Cell centres at (i - kGhost) dx: node i of [0,100]^2 is sample i + kGhost.
  const GridSpec<2> spec(Vec2::Constant(-(kGhost + 0.5) * dx), dx, IVec2::Constant(n));
  MacGrid<2> velocity(spec);
  for (int a = 0; a < 2; ++a) {
    auto& g = velocity.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec2 p = g.position(g.coord(i));
      g[i] = static_cast<float>(a == 0 ? kOmega * (50.0 - p.y()) : kOmega * (p.x() - 50.0));
    }
  }
  AdvectionSettings settings;
  settings.block = block;
  settings.scheme = scheme;
  settings.limiter = ExtremaLimiter::None;
  settings.trace = BackTrace::Euler;
  Advector<double, 2> advector(spec, settings);
  Grid<double, 2> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = slottedDisc(phi.position(phi.coord(i)));
  std::vector<std::size_t> ghosts;
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const IVec2 c = phi.coord(i);
    if ((c.array() < kGhost).any() || (c.array() >= kGhost + nodes).any()) ghosts.push_back(i);
  }
  const double dt = cfl * dx / (kOmega * 100.0);  // max(|u| + |v|) = 100 omega at the corners
  double t = 0.0;
  while (t < kOneTurn - 1e-9) {
    const double step = std::min(dt, kOneTurn - t);
    advector.advect(phi, velocity, step);
    t += step;
    for (std::size_t i : ghosts) phi[i] = exact(phi.position(phi.coord(i)), t);
  }
  std::vector<double> error(static_cast<std::size_t>(nodes) * nodes);
  for (int j = 0; j < nodes; ++j)
    for (int i = 0; i < nodes; ++i) {
      const IVec2 c(i + kGhost, j + kGhost);
      error[static_cast<std::size_t>(j) * nodes + i] = std::abs(phi(c) - slottedDisc(phi.position(c)));
    }
  return error;
}

double mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

// Ch. 2.8: mean over coincident nodes of log2(e(i,j) / e'(2i-1, 2j-1)) (1-based indices).
double pointwiseOrder(const std::vector<double>& coarse, int nodes, const std::vector<double>& fine) {
  const int fineNodes = 2 * nodes - 1;
  double sum = 0.0;
  int count = 0;
  for (int j = 0; j < nodes; ++j)
    for (int i = 0; i < nodes; ++i) {
      const double e = coarse[static_cast<std::size_t>(j) * nodes + i];
      const double f = fine[static_cast<std::size_t>(2 * j) * fineNodes + 2 * i];
      if (e > 0.0 && f > 0.0) {
        sum += std::log2(e / f);
        ++count;
      }
    }
  return sum / count;
}

// One printed value of Selle's tables and whether this setup reproduces it (checked) or not
// (printed only; docs/advection.md has our numbers and the reasons).
struct Entry {
  double selle;
  bool checked;
};
constexpr Entry ok(double v) { return {v, true}; }
constexpr Entry no(double v) { return {v, false}; }

struct FigureColumn {
  const char* name;
  AdvectionScheme scheme;
  int ctestNodes;            // finest grid the ctest run goes to (the DISABLED_ tests go to 401^2)
  std::vector<Entry> error;  // grid sizes 101^2, 201^2, 401^2 (801^2 and 1601^2 are not run)
  std::vector<Entry> order;  // 201^2, 401^2
};

// Runs each column on grids 101^2, 201^2, ... up to its ctestNodes (or `finest`, if given) and
// checks the checked entries: errors within 15 %, orders within 0.1.
void reproduceFigure(BuildingBlock block, double cfl, const std::vector<FigureColumn>& table, int finest = 0) {
  for (const FigureColumn& col : table) {
    std::vector<double> previous;
    // The sanitizer build stops at 201^2: the same errors and the first order, minutes sooner.
    const int top = finest ? finest : test::fullOrSanitized(col.ctestNodes, std::min(col.ctestNodes, 201));
    for (int k = 0, nodes = 101; nodes <= top; ++k, nodes = 2 * nodes - 1) {
      const std::vector<double> errors = nodeErrors(nodes, block, col.scheme, cfl);
      const double e = mean(errors);
      const Entry& se = col.error[k];
      std::cout << fmt::format("{:28s} {:4d}^2 error {:.3e} (Selle {:.1e}{})", col.name, nodes, e, se.selle,
                               se.checked ? "" : ", not checked");
      if (se.checked) {
        EXPECT_NEAR(e, se.selle, 0.15 * se.selle) << col.name << " " << nodes << "^2";
      }
      if (k) {
        const double order = pointwiseOrder(previous, (nodes + 1) / 2, errors);
        const Entry& so = col.order[k - 1];
        std::cout << fmt::format("  order {:.2f} (Selle {:.2f}{})", order, so.selle, so.checked ? "" : ", not checked");
        if (so.checked) {
          EXPECT_NEAR(order, so.selle, 0.1) << col.name << " " << nodes << "^2";
        }
      }
      std::cout << "\n";
      previous = errors;
    }
  }
}

// Selle's tables. From 201^2 on our second-order schemes are more accurate than his (BFECC by
// 16-30 %, MacCormack by 12-13 % at 201^2 and 21-23 % at 401^2) and their orders higher (2.1-2.3
// against his 1.6-1.95); those entries are printed, not checked (docs/advection.md).

const std::vector<FigureColumn> kFigure2_6 = {
    {"upwind", AdvectionScheme::FirstOrder, 401, {ok(1.8), ok(9.6e-1), ok(5.2e-1)}, {ok(1.05), ok(1.04)}},
    {"BFECC (upwind)", AdvectionScheme::BFECC, 201, {ok(8.9e-2), no(3.9e-2), no(1.8e-2)}, {no(1.79), no(1.77)}},
    {"MacCormack (upwind)", AdvectionScheme::MacCormack, 201,
     {ok(1.6e-1), ok(6.3e-2), no(3.2e-2)}, {no(1.93), no(1.59)}},
};
const std::vector<FigureColumn> kFigure2_7 = {
    {"semi-Lagrangian", AdvectionScheme::FirstOrder, 401, {ok(1.8), ok(1.0), ok(5.4e-1)}, {ok(1.04), ok(1.03)}},
    {"BFECC (semi-Lagrangian)", AdvectionScheme::BFECC, 201,
     {ok(9.9e-2), no(4.1e-2), no(2.0e-2)}, {no(1.73), no(1.67)}},
    {"MacCormack (semi-Lagrangian)", AdvectionScheme::MacCormack, 201,
     {ok(1.7e-1), ok(6.7e-2), no(3.3e-2)}, {no(1.95), no(1.60)}},
};
const std::vector<FigureColumn> kFigure2_8 = {
    {"semi-Lagrangian", AdvectionScheme::FirstOrder, 401, {ok(2.0), ok(1.1), ok(5.6e-1)}, {ok(1.02), ok(1.02)}},
    {"BFECC (semi-Lagrangian)", AdvectionScheme::BFECC, 201,
     {ok(5.4e-2), no(2.4e-2), no(1.0e-2)}, {no(1.81), no(1.84)}},
    {"MacCormack (semi-Lagrangian)", AdvectionScheme::MacCormack, 201,
     {ok(1.5e-1), ok(6.0e-2), no(3.0e-2)}, {no(1.82), no(1.62)}},
};

}  // namespace

TEST(ZalesakDisc, Figure2_6_UpwindBuildingBlocksCfl075) { reproduceFigure(BuildingBlock::Upwind, 0.75, kFigure2_6); }

TEST(ZalesakDisc, Figure2_7_SemiLagrangianBuildingBlocksCfl075) {
  reproduceFigure(BuildingBlock::SemiLagrangian, 0.75, kFigure2_7);
}

TEST(ZalesakDisc, Figure2_8_SemiLagrangianBuildingBlocksCfl175) {
  reproduceFigure(BuildingBlock::SemiLagrangian, 1.75, kFigure2_8);
}

// Every column to 401^2, for docs/advection.md (minutes; --gtest_also_run_disabled_tests).
TEST(ZalesakDisc, DISABLED_Figure2_6_To401) { reproduceFigure(BuildingBlock::Upwind, 0.75, kFigure2_6, 401); }
TEST(ZalesakDisc, DISABLED_Figure2_7_To401) { reproduceFigure(BuildingBlock::SemiLagrangian, 0.75, kFigure2_7, 401); }
TEST(ZalesakDisc, DISABLED_Figure2_8_To401) { reproduceFigure(BuildingBlock::SemiLagrangian, 1.75, kFigure2_8, 401); }
