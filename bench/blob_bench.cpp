// Blob rendering (Stam ch. 5.3-5.4, App. 5.C): 3000 overlapping Gaussian blobs in a unit ball (a
// cloud, about 70 blobs per ray), 320 x 240, one directional light with blob-to-blob shadows.
// Counters: seconds for the shadows and for the camera rays, blob-ray pairs per ray.
#include <benchmark/benchmark.h>

#include "msim/core/rng.hpp"
#include "msim/render/blobs.hpp"

using namespace msim;

namespace {

void BM_RenderBlobs(benchmark::State& state) {
  Rng rng(7);
  std::vector<render::Blob> blobs;
  while (blobs.size() < static_cast<std::size_t>(state.range(0))) {
    const Vec3 p(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    if (p.norm() < 1.0) blobs.push_back({p, 0.002, rng.uniform(0.04, 0.1)});
  }
  const render::BlobSet set(std::move(blobs));
  render::Camera camera;
  camera.position = Vec3(0.0, 0.5, 4.0);
  camera.target = Vec3::Zero();
  camera.width = 320;
  camera.height = 240;
  render::Light light;
  light.direction = Vec3(-1.0, -1.0, -0.3);
  light.intensity = 3.0;
  render::Medium medium;
  medium.extinction = 10.0;
  render::BlobRenderStats total;
  for (auto _ : state) {
    const render::BlobRenderResult r = render::renderBlobs(set, camera, {light}, medium, render::VolumeRenderSettings{});
    total.secondsShadows += r.stats.secondsShadows;
    total.secondsRays += r.stats.secondsRays;
    total.rays = r.stats.rays;
    total.blobRayPairs = r.stats.blobRayPairs;
    benchmark::DoNotOptimize(r.image.rgb.data());
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["s_shadows"] = total.secondsShadows / iterations;
  state.counters["s_rays"] = total.secondsRays / iterations;
  state.counters["blobs_per_ray"] = static_cast<double>(total.blobRayPairs) / static_cast<double>(total.rays);
}

}  // namespace

BENCHMARK(BM_RenderBlobs)->Arg(3000)->Unit(benchmark::kMillisecond)->Iterations(3);
