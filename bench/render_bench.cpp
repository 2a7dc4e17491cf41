// The physically based volume renderer (Stam ch. 5, single scattering) on a 128^3 smoke-like
// density (Gaussian puffs modulated by a few sine octaves, exactly zero away from the puffs as a
// simulation's density is) at 640 x 480 with one shadowing directional light and sky light.
// Counters: seconds spent on the light transmittance grid and on the camera rays, rays/s and
// density samples per second of the march.
#include <benchmark/benchmark.h>

#include <cmath>

#include "msim/render/frame_renderer.hpp"
#include "msim/render/volume_renderer.hpp"

using namespace msim;

namespace {

Grid<float, 3> smokePuffs(int n) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, IVec3::Constant(n));
  Grid<float, 3> rho(spec);
  const Vec3 centres[] = {{0.5, 0.35, 0.5}, {0.38, 0.5, 0.45}, {0.62, 0.55, 0.55}, {0.5, 0.7, 0.5}, {0.45, 0.82, 0.58}};
  const double radii[] = {0.14, 0.12, 0.12, 0.11, 0.08};
  for (std::size_t i = 0; i < rho.count(); ++i) {
    const Vec3 x = rho.position(rho.coord(i));
    double d = 0.0;
    for (int k = 0; k < 5; ++k) d += std::exp(-(x - centres[k]).squaredNorm() / (2.0 * radii[k] * radii[k]));
    const double detail = std::sin(23.0 * x[0] + 3.0 * std::sin(17.0 * x[1])) * std::sin(19.0 * x[1] + 2.0 * x[2]) *
                          std::sin(29.0 * x[2] + 5.0 * x[0]);
    const double value = 2.0 * d * (0.7 + 0.3 * detail) - 0.05;
    rho[i] = value > 0.0 ? static_cast<float>(value) : 0.0f;
  }
  return rho;
}

render::Light benchSun() {
  render::Light sun;
  sun.type = render::Light::Type::Directional;
  sun.direction = Vec3(0.5, -1.0, -0.3);
  sun.intensity = 10.0;
  return sun;
}

// Renders `input` at 640 x 480 (framing its density's box) for every iteration and reports the
// cost split: light grids, march, rays/s, samples, surface pixels.
void runRenderVolume(benchmark::State& state, const render::VolumeInput& input) {
  const GridSpec<3>& spec = input.density->spec();
  const render::Camera camera = render::frameBox(spec.origin, spec.upper(), 640, 480);
  render::RenderStats total;
  for (auto _ : state) {
    const render::RenderResult r =
        render::renderVolume(input, camera, {benchSun()}, render::Medium(), render::VolumeRenderSettings());
    total.secondsLightGrids += r.stats.secondsLightGrids;
    total.secondsMarch += r.stats.secondsMarch;
    total.primaryRays += r.stats.primaryRays;
    total.samples += r.stats.samples;
    total.surfaceHits += r.stats.surfaceHits;
    benchmark::DoNotOptimize(r.image.rgb.data());
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["s_light_grids"] = total.secondsLightGrids / iterations;
  state.counters["s_march"] = total.secondsMarch / iterations;
  state.counters["rays_per_s"] = static_cast<double>(total.primaryRays) / (total.secondsLightGrids + total.secondsMarch);
  state.counters["samples_per_s"] = static_cast<double>(total.samples) / total.secondsMarch;
  state.counters["samples_per_ray"] = static_cast<double>(total.samples) / static_cast<double>(total.primaryRays);
  if (total.surfaceHits > 0) state.counters["surface_pixels"] = static_cast<double>(total.surfaceHits) / iterations;
}

void BM_RenderVolume(benchmark::State& state) {
  const Grid<float, 3> rho = smokePuffs(static_cast<int>(state.range(0)));
  runRenderVolume(state, render::VolumeInput{&rho});
}

// The same with a solid ball (radius 0.15, lower middle of the box, partly inside the lower puffs)
// given as a signed-distance grid: sphere tracing of the camera rays, the surface shading, and the
// visibility carried through the light sweep.
void BM_RenderVolumeWithBall(benchmark::State& state) {
  const Grid<float, 3> rho = smokePuffs(static_cast<int>(state.range(0)));
  Grid<float, 3> ball(rho.spec());
  for (std::size_t i = 0; i < ball.count(); ++i)
    ball[i] = static_cast<float>((ball.position(ball.coord(i)) - Vec3(0.5, 0.3, 0.55)).norm() - 0.15);
  render::VolumeInput input{&rho};
  input.surfaceDistance = &ball;
  runRenderVolume(state, input);
}

// Issue #4's figure: the whole picture with multiple scattering (light grid, first-scatter source,
// diffusion solve, march), as `msim render` makes it.
void BM_RenderFrameWithMultipleScattering(benchmark::State& state) {
  const Grid<float, 3> rho = smokePuffs(static_cast<int>(state.range(0)));
  render::FrameRenderConfig config;
  config.lights = {benchSun()};
  render::FrameTimings total;
  for (auto _ : state) {
    const render::FrameResult r = render::renderFrame(config, rho);
    total.lights += r.timings.lights;
    total.multipleScattering += r.timings.multipleScattering;
    total.march += r.timings.march;
    total.diffusionCycles = r.timings.diffusionCycles;
    benchmark::DoNotOptimize(r.render.image.rgb.data());
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["s_light_grids"] = total.lights / iterations;
  state.counters["s_multiple_scattering"] = total.multipleScattering / iterations;
  state.counters["s_march"] = total.march / iterations;
  state.counters["diffusion_cycles"] = total.diffusionCycles;
}

// One light's transmittance grid at 128^3 (the sweep of lightTransmittance): range(1) = 0 the
// directional sun, 1 a point light above the box, 2 a point light inside it.
void BM_LightTransmittance(benchmark::State& state) {
  const Grid<float, 3> rho = smokePuffs(static_cast<int>(state.range(0)));
  render::Light light = benchSun();
  if (state.range(1) > 0) {
    light.type = render::Light::Type::Point;
    light.position = state.range(1) == 1 ? Vec3(0.8, 1.6, 0.3) : Vec3(0.5, 0.6, 0.5);
  }
  for (auto _ : state) benchmark::DoNotOptimize(render::lightTransmittance(rho, light, render::Medium(), 0.5).data().data());
}

}  // namespace

BENCHMARK(BM_LightTransmittance)->Args({128, 0})->Args({128, 1})->Args({128, 2})->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_RenderVolume)->Arg(128)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_RenderVolumeWithBall)->Arg(128)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_RenderFrameWithMultipleScattering)->Arg(128)->Unit(benchmark::kMillisecond)->Iterations(5);
