// Fire in the preview: hot emitter cells glow with their black-body colour where they are, and
// smoke in front of them dims them.
#include <gtest/gtest.h>

#include "msim/render/density_preview.hpp"

using namespace msim;
using namespace msim::render;

namespace {

struct Scene3 {
  GridSpec<3> spec{Vec3::Zero(), 0.1, IVec3(16, 16, 16)};
  Grid<float, 3> smoke{spec, 0.0f}, flame{spec, 0.0f}, temperature{spec, 293.0f};
};

const Grid<float, 3>* const kNoSolid = nullptr;

PreviewSettings settings() {
  PreviewSettings s;
  s.minWidth = 16;  // one pixel per cell
  s.emissionScale = 2.0;
  return s;
}

}  // namespace

TEST(PreviewEmission, HotFlameGlowsOrangeWhereItIs) {
  Scene3 sc;
  sc.flame(IVec3(4, 10, 8)) = 1.0f;
  sc.temperature(IVec3(4, 10, 8)) = 1500.0f;
  const io::Image dark = renderDensityPreview(sc.smoke, settings(), kNoSolid);
  const io::Image lit = renderDensityPreview(sc.smoke, settings(), kNoSolid, PreviewEmission<3>{&sc.flame, &sc.temperature});
  const int row = 15 - 10;  // image rows run downwards
  const std::uint8_t* fire = lit.pixel(4, row);
  EXPECT_GT(fire[0], fire[1]);  // red > green > blue: a 1500 K black body
  EXPECT_GT(fire[1], fire[2]);
  EXPECT_GT(fire[0], dark.pixel(4, row)[0] + 100);
  EXPECT_EQ(lit.pixel(12, 3)[0], dark.pixel(12, 3)[0]);  // elsewhere nothing changes
}

TEST(PreviewEmission, ColdEmitterAndSmokeInFrontDimTheGlow) {
  Scene3 sc;
  sc.flame(IVec3(4, 10, 2)) = 1.0f;  // at the back (the camera looks down -z from z = max)
  const PreviewEmission<3> emission{&sc.flame, &sc.temperature};
  const io::Image cold = renderDensityPreview(sc.smoke, settings(), kNoSolid, emission);
  const io::Image none = renderDensityPreview(sc.smoke, settings(), kNoSolid);
  EXPECT_EQ(cold.pixel(4, 5)[0], none.pixel(4, 5)[0]);  // 293 K emits nothing visible
  sc.temperature(IVec3(4, 10, 2)) = 1500.0f;
  PreviewSettings black = settings();  // smoke that only absorbs, so it cannot add light of its own
  black.albedo = 0.0;
  black.ambient = 0.0;
  const int clear = renderDensityPreview(sc.smoke, black, kNoSolid, emission).pixel(4, 5)[0];
  for (int z = 8; z < 12; ++z) sc.smoke(IVec3(4, 10, z)) = 1.0f;
  const int behindSmoke = renderDensityPreview(sc.smoke, black, kNoSolid, emission).pixel(4, 5)[0];
  EXPECT_LT(behindSmoke, clear - 30);
}
