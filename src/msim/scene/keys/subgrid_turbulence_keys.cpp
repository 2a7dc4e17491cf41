#include "msim/scene/keys/subgrid_turbulence_keys.hpp"

namespace msim::scene {

void declareSubgridTurbulenceKeys(Schema& turbulence, const char* enabledNote, double defaultViscosity) {
  turbulence.boolean("enabled", false, enabledNote);
  turbulence.integer("refinement", 4, "fine cells per simulation cell and axis (the seed: 4)").min(1).max(8);
  turbulence.number("largest_eddy", "m", 0.0, "l_0, size of the largest modelled eddies; 0 = four grid cells").min(0.0);
  turbulence.number("viscosity", "m^2/s", defaultViscosity,
                    "nu: sets the viscous cutoff that turns turbulence off in calm flow")
      .min(0.0);
  turbulence.number("eddy_viscosity_constant", "", 0.09,
                    "C in the eddy viscosity nu_t = C l_0 sqrt(E_0) (eq. 3.6, 3.8): 0.09 = k-epsilon's C_mu; 1 = the seed")
      .min(0.0, Bound::Exclusive);
  turbulence.number("initial_energy", "m^2/s^2", 1e-4, "E_0 at the start (production needs E_0 > 0)").min(0.0);
  turbulence.number("intensity", "", 1.0,
                    "scales the eddies' speed (1: the seed's calibration, eddies of speed sqrt(E_i) per octave)")
      .min(0.0);
  turbulence.integer("octaves", 0, "noise octaves; 0 = down to two fine cells").min(0).max(8);
  turbulence.integer("seed", 1, "random seed of the noise").min(0);
}

turbulence::SubgridTurbulenceParams subgridTurbulenceParams(const nlohmann::json& t) {
  turbulence::SubgridTurbulenceParams k;
  k.refinement = t.at("refinement").get<int>();
  k.energy.largestEddy = t.at("largest_eddy").get<double>();
  k.energy.viscosity = t.at("viscosity").get<double>();
  k.energy.initialEnergy = t.at("initial_energy").get<double>();
  k.energy.eddyViscosityConstant = t.at("eddy_viscosity_constant").get<double>();
  k.particles.octaves = t.at("octaves").get<int>();
  k.particles.seed = t.at("seed").get<std::uint64_t>();
  k.particles.intensity = t.at("intensity").get<double>();
  return k;
}

}  // namespace msim::scene
