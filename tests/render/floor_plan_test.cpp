// Top views of 2D scenes: disc areas, colours through the colour map, obstacle polygons, errors.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "expect_invalid.hpp"
#include "msim/render/floor_plan.hpp"

using namespace msim;
using namespace msim::render;

namespace {

double linear(std::uint8_t srgb) {
  const double s = srgb / 255.0;
  return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

}  // namespace

TEST(FloorPlan, DiscCoversItsAreaWithAntialiasedEdges) {
  FloorPlan plan;
  plan.lo = Vec2(0, 0);
  plan.hi = Vec2(10, 10);
  plan.width = 200;  // 0.05 m pixels
  plan.floor = Vec3::Ones();
  const double r = 2.1;
  const io::Image image = renderFloorPlan(plan, Discs{{Vec2(4.97, 5.03)}, {r}, {}});
  double covered = 0.0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) covered += (1.0 - linear(image.pixel(x, y)[0])) / (1.0 - 0.35);
  const double pixelArea = 0.05 * 0.05;
  EXPECT_NEAR(covered * pixelArea, std::numbers::pi * r * r, 0.003 * std::numbers::pi * r * r);
}

TEST(FloorPlan, ValuesMapToTheColourMapAndObstaclesAreFilled) {
  FloorPlan plan;
  plan.hi = Vec2(4, 2);
  plan.width = 400;  // 0.01 m pixels, 400 x 200
  plan.valueMin = 1.0;
  plan.valueMax = 3.0;
  const Discs discs{{Vec2(0.5, 1.0), Vec2(1.5, 1.0)}, {0.2}, {1.0, 3.0}};
  const std::vector<std::vector<Vec2>> walls = {{Vec2(3, 0.5), Vec2(3.5, 0.5), Vec2(3.5, 1.5), Vec2(3, 1.5)}};
  const io::Image image = renderFloorPlan(plan, discs, walls);
  EXPECT_EQ(image.height, 200);
  for (const auto& [x, t] : {std::pair{50, 0.0}, std::pair{150, 1.0}}) {
    const Vec3 expected = colourMap(t);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(linear(image.pixel(x, 100)[c]), expected[c], 0.01) << x;
  }
  int wallPixels = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) wallPixels += std::abs(linear(image.pixel(x, y)[0]) - 0.25) < 0.01;
  EXPECT_NEAR(wallPixels, 50 * 100, 150);  // the 0.5 x 1 m wall
  EXPECT_LT(colourMap(0.0).sum(), colourMap(0.5).sum());  // dark to bright
  EXPECT_LT(colourMap(0.5).sum(), colourMap(1.0).sum());
}

TEST(FloorPlan, CellFieldColoursTheFloorWhereItIsPositive) {
  FloorPlan plan;
  plan.hi = Vec2(4, 2);
  plan.width = 400;  // 0.01 m pixels, 400 x 200; row 150 is y = 0.495
  plan.valueMin = 1.0;
  plan.valueMax = 3.0;
  const std::vector<float> values{2.0f, 0.0f};  // two 1 m cells over [0, 2] x [0, 1]
  const CellField field{GridSpec<2>(Vec2(0, 0), 1.0, IVec<2>(2, 1)), values};
  const io::Image image = renderFloorPlan(plan, Discs{}, {}, &field);
  const Vec3 mid = colourMap(0.5);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(linear(image.pixel(50, 150)[c]), mid[c], 0.01);          // the cell holding 2
    EXPECT_NEAR(linear(image.pixel(150, 150)[c]), plan.floor[c], 0.01);  // the cell holding 0
    EXPECT_NEAR(linear(image.pixel(300, 150)[c]), plan.floor[c], 0.01);  // beyond the field
    EXPECT_NEAR(linear(image.pixel(50, 50)[c]), plan.floor[c], 0.01);    // above it
  }
  const std::vector<float> short_{1.0f};
  const CellField wrong{field.spec, short_};
  expectInvalidArgument([&] { renderFloorPlan(plan, Discs{}, {}, &wrong); }, "field values");
}

TEST(FloorPlan, BadInputIsRefused) {
  FloorPlan plan;
  expectInvalidArgument([&] { renderFloorPlan(plan, Discs{{Vec2(0.5, 0.5), Vec2(0.2, 0.2)}, {0.1, 0.1, 0.1}, {}}); },
                        "radii");
  expectInvalidArgument([&] { renderFloorPlan(plan, Discs{{Vec2(0.5, 0.5)}, {0.1}, {1.0, 2.0}}); }, "values");
  expectInvalidArgument([&] { renderFloorPlan(plan, Discs{{Vec2(0.5, 0.5)}, {-0.1}, {}}); }, "positive");
  plan.hi = plan.lo;
  expectInvalidArgument([&] { renderFloorPlan(plan, Discs{}); }, "box");
}
