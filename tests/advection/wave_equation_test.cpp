// Selle Tables 2.2 and 2.3: u_t + u_x = 0, u(0,x) = sin(4 pi x), periodic on [0,1], to t = 0.5
// (one period). "n" is the number of grid nodes including both ends of the period, so
// dx = 1/(n-1) and the periodic grid has n-1 distinct samples; "Error" is the average magnitude
// (1/n) sum |u_i - u(x_i, t)| (ch. 2.6) and "Order" is log2 of the ratio of successive errors.
// The 1D problem runs on an (n-1) x 1 periodic 2D grid of doubles through the same Advector the
// simulations use.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "msim/numerics/advection/advector.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr double kFinalTime = 0.5;

double averageError(int n, double cfl, const AdvectionSettings& settings) {
  const double dx = 1.0 / (n - 1);
  const GridSpec<2> spec(Vec2::Zero(), dx, IVec2(n - 1, 1));
  MacGrid<2> velocity(spec);
  velocity.component(0).fill(1.0f);
  Grid<double, 2> u(spec, IVec2(n - 1, 1), Vec2(0.0, 0.5));  // samples on the nodes x_i = i dx
  for (int i = 0; i < n - 1; ++i) u[i] = std::sin(4.0 * std::numbers::pi * i * dx);
  Advector<double, 2> advector(spec, settings, allPeriodic<2>());
  const double dt = cfl * dx;
  double t = 0.0;
  while (t < kFinalTime - 1e-12) {
    const double step = std::min(dt, kFinalTime - t);  // the last step lands on t = 0.5 exactly
    advector.advect(u, velocity, step);
    t += step;
  }
  double sum = 0.0;
  for (int i = 0; i < n - 1; ++i) sum += std::abs(u[i] - std::sin(4.0 * std::numbers::pi * (i * dx - t)));
  return sum / (n - 1);
}

struct Column {
  const char* name;
  AdvectionScheme scheme;
  std::vector<double> error;  // Selle's errors for n = 101, 201, 401, 801
  // Selle's orders for n = 201, 401, 801. Where a printed order contradicts the printed errors
  // (MacCormack, Table 2.3, n = 201: 2.21, yet log2(5.3e-3 / 1.3e-3) = 2.03 and no rounding of
  // those errors reaches 2.11) the order of the printed errors is used; see docs/advection.md.
  std::vector<double> order;
};

void reproduce(BuildingBlock block, double cfl, const std::vector<Column>& table) {
  const int sizes[] = {101, 201, 401, 801};
  for (const Column& col : table) {
    AdvectionSettings settings;
    settings.block = block;
    settings.scheme = col.scheme;
    settings.limiter = ExtremaLimiter::None;  // Tables 2.2/2.3 are the unlimited schemes
    double previous = 0.0;
    for (int k = 0; k < 4; ++k) {
      const double e = averageError(sizes[k], cfl, settings);
      const double order = k ? std::log2(previous / e) : 0.0;
      std::cout << fmt::format("{:10s} n={:4d} error {:.3e} (Selle {:.1e})", col.name, sizes[k], e, col.error[k]);
      if (k) std::cout << fmt::format("  order {:.2f} (Selle {:.2f})", order, col.order[k - 1]);
      std::cout << "\n";
      EXPECT_NEAR(e, col.error[k], 0.15 * col.error[k]) << col.name << " n=" << sizes[k];
      if (k) {
        EXPECT_NEAR(order, col.order[k - 1], 0.1) << col.name << " n=" << sizes[k];
      }
      previous = e;
    }
  }
}

}  // namespace

TEST(WaveEquation, Table2_2_UpwindBuildingBlocksCfl075) {
  reproduce(BuildingBlock::Upwind, 0.75,
            {{"upwind", AdvectionScheme::FirstOrder, {6.0e-2, 3.1e-2, 1.6e-2, 7.8e-3}, {1.02, 1.01, 1.00}},
             {"BFECC", AdvectionScheme::BFECC, {1.3e-3, 3.3e-4, 8.2e-5, 2.1e-5}, {2.09, 1.97, 1.99}},
             {"MacCormack", AdvectionScheme::MacCormack, {4.7e-3, 1.2e-3, 2.9e-4, 7.2e-5}, {1.96, 2.01, 2.00}}});
}

TEST(WaveEquation, Table2_3_SemiLagrangianBuildingBlocksCfl175) {
  reproduce(BuildingBlock::SemiLagrangian, 1.75,
            {{"semi-Lag", AdvectionScheme::FirstOrder, {2.6e-2, 1.3e-2, 6.7e-3, 3.3e-3}, {0.98, 1.02, 1.02}},
             {"BFECC", AdvectionScheme::BFECC, {5.6e-4, 1.4e-4, 3.5e-5, 8.8e-6}, {2.09, 1.96, 1.99}},
             {"MacCormack", AdvectionScheme::MacCormack, {5.3e-3, 1.3e-3, 3.4e-4, 8.4e-5}, {2.03, 2.05, 2.05}}});
}
