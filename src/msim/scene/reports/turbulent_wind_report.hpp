#pragma once
// What a run with turbulent winds leaves besides its frames: each wind's measured energy spectrum
// against the prescribed Kolmogorov spectrum (winds/wind_N_spectrum.csv and .png) and, in
// run.json's results, its measured speed rms, spectrum exponent and divergence.
#include <filesystem>
#include <span>

#include <nlohmann/json.hpp>

#include "msim/turbulence/turbulent_wind.hpp"

namespace msim::scene {

// Writes the reports and returns run.json's results: {"winds": [one object per wind]}, or an empty
// object without winds.
template <int D>
nlohmann::json writeWindReports(std::span<const turbulence::TurbulentWind<D>> winds, const std::filesystem::path& runDir);

}  // namespace msim::scene
