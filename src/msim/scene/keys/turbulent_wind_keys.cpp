#include "msim/scene/keys/turbulent_wind_keys.hpp"

#include <fmt/format.h>

#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {

using nlohmann::json;

void declareTurbulentWinds(Schema& root) {
  Schema wind = Schema::object(
      "a turbulent wind: an isotropic, incompressible random field with the Kolmogorov spectrum, synthesised on a "
      "lattice periodic in space and time (Stam ch. 3.4) and carried by its mean velocity");
  wind.string("synthesis", "spectral",
              "'spectral': FFT on a lattice periodic in space and time (ch. 3.3.2); 'spatial': sparse convolution "
              "(ch. 3.3.3), evaluated anywhere without a lattice, never repeating, frozen in time")
      .choices({"spectral", "spatial"});
  wind.number("speed_rms", "m/s", 0.1, "sqrt(<|u'|^2>) of the turbulent part; sets the dissipation rate epsilon")
      .min(0.0, Bound::Exclusive);
  wind.number("dissipation", "m^2/s^3", 0.0, "epsilon of E(k) = C_K epsilon^(2/3) k^(-5/3); 0 = from speed_rms").min(0.0);
  wind.number("kolmogorov_constant", "", 1.5, "C_K").min(0.0, Bound::Exclusive);
  wind.number("tile", "m", 0.0, "side of the periodic lattice tile; 0 = the domain's longest side").min(0.0);
  wind.number("largest_eddy", "m", 0.0, "L: no energy in longer waves; 0 = tile / 4 (the seed's 1/L = 4)").min(0.0);
  wind.number("smallest_eddy", "m", 0.0, "l_0, the cutoff: no energy in shorter waves; 0 = two lattice cells").min(0.0);
  wind.integer("resolution", 16, "lattice samples per axis (the seed: 16)").min(4);
  wind.integer("time_samples", 16, "lattice samples over the period (the seed: 16; 1 = frozen)").min(1);
  wind.number("period", "s", 4.0, "the lattice repeats after this time").min(0.0, Bound::Exclusive);
  wind.number("sweep", "m/s", -1.0,
              "sigma of eq. 3.28: waves of wavenumber k decorrelate at the rate k sigma; -1 = speed_rms (small eddies "
              "swept by the large ones)")
      .min(-1.0);
  wind.integer("seed", 1, "random seed of the realisation").min(0);
  wind.number("reach", "", 2.0, "spatial: kernel reach in largest eddies").min(1.0);
  wind.integer("points_per_cell", 8, "spatial: random impulses per cell of the kernel's reach").min(1).max(64);
  wind.vector("origin", "m", {0.0, 0.0, 0.0}, "where the lattice's first sample sits").lengths({2, 3});
  wind.vector("mean_velocity", "m/s", {0.0, 0.0, 0.0}, "U: u = U + u'(x - origin - U t, t) (frozen turbulence carried by the mean wind)")
      .lengths({2, 3});
  root.array("winds", wind, "turbulent winds, summed");
}

template <int D>
std::vector<turbulence::TurbulentWind<D>> turbulentWinds(const Scene& scene) {
  const json& winds = scene.resolved.at("winds");
  const json& domain = scene.resolved.at("domain");
  const Vec3 lo = paddedVec3(domain.at("min")), hi = paddedVec3(domain.at("max"));
  double longest = 0.0;
  for (int a = 0; a < D; ++a) longest = std::max(longest, hi[a] - lo[a]);
  std::vector<turbulence::TurbulentWind<D>> out;
  for (std::size_t i = 0; i < winds.size(); ++i) {
    const json& w = winds[i];
    const std::string where = fmt::format("{}: winds[{}]", scene.file.string(), i);
    turbulence::SpectralWindParams p;
    p.resolution = w.at("resolution").get<int>();
    p.timeSamples = w.at("time_samples").get<int>();
    p.size = w.at("tile").get<double>() > 0.0 ? w.at("tile").get<double>() : longest;
    p.period = w.at("period").get<double>();
    p.sweep = w.at("sweep").get<double>();
    p.seed = w.at("seed").get<std::uint64_t>();
    p.spectrum.kolmogorovConstant = w.at("kolmogorov_constant").get<double>();
    p.spectrum.largestEddy = w.at("largest_eddy").get<double>() > 0.0 ? w.at("largest_eddy").get<double>() : p.size / 4;
    p.spectrum.smallestEddy =
        w.at("smallest_eddy").get<double>() > 0.0 ? w.at("smallest_eddy").get<double>() : 2.0 * p.size / p.resolution;
    const double epsilon = w.at("dissipation").get<double>();
    // Validate the range before deriving epsilon from it; then the whole set.
    p.spectrum.dissipation = 1.0;
    p.spectrum.validate(where);
    p.spectrum.dissipation = epsilon > 0.0 ? epsilon : p.spectrum.dissipationForSpeedRms(w.at("speed_rms").get<double>());
    const Vec<D> origin = sceneVector<D>(w.at("origin")), mean = sceneVector<D>(w.at("mean_velocity"));
    if (w.at("synthesis").get<std::string>() == "spatial") {
      turbulence::SparseConvolutionParams sp;
      sp.spectrum = p.spectrum;
      sp.reach = w.at("reach").get<double>();
      sp.pointsPerCell = w.at("points_per_cell").get<int>();
      sp.seed = p.seed;
      out.emplace_back(turbulence::SparseConvolutionWind<D>(sp, where), p.spectrum.speedRms(), origin, mean);
    } else {
      out.emplace_back(turbulence::SpectralWind<D>(p, where), origin, mean);
    }
  }
  return out;
}

template std::vector<turbulence::TurbulentWind<2>> turbulentWinds<2>(const Scene&);
template std::vector<turbulence::TurbulentWind<3>> turbulentWinds<3>(const Scene&);

}  // namespace msim::scene
