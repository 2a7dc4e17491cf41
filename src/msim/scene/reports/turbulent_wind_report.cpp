#include "msim/scene/reports/turbulent_wind_report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "msim/io/atomic_file.hpp"
#include "msim/io/png.hpp"
#include "msim/render/plot.hpp"
#include "msim/scene/reports/spectrum_plot.hpp"
#include "msim/turbulence/energy_spectrum.hpp"

namespace msim::scene {

namespace fs = std::filesystem;
using nlohmann::json;

template <int D>
json writeWindReports(std::span<const turbulence::TurbulentWind<D>> winds, const fs::path& runDir) {
  json out = json::array();
  if (winds.empty()) return json::object();
  for (std::size_t i = 0; i < winds.size(); ++i) {
    if (!winds[i].lattice()) {
      out.push_back({{"synthesis", "spatial"}});  // no lattice to measure
      continue;
    }
    fs::create_directories(runDir / "winds");
    const auto& lattice = *winds[i].lattice();
    const auto& p = lattice.params();
    const turbulence::ShellSpectrum measured = turbulence::shellSpectrum<D>(lattice.timeSlice(0), p.resolution, p.size);
    const turbulence::DivergenceMeasure div = turbulence::spectralDivergence<D>(lattice.timeSlice(0), p.resolution, p.size);
    double meanSquare = 0.0;
    for (const auto& u : lattice.samples()) meanSquare += u.template cast<double>().squaredNorm();
    meanSquare /= static_cast<double>(lattice.samples().size());

    const std::string stem = fmt::format("wind_{}_spectrum", i);
    io::writeFileAtomically(runDir / "winds" / (stem + ".csv"), [&](const fs::path& tmp) {
      std::ofstream csv(tmp, std::ios::binary);
      csv << "k_rad_per_m,E_measured,E_prescribed,modes\n";
      for (std::size_t s = 0; s < measured.wavenumber.size(); ++s)
        csv << fmt::format("{:.6g},{:.6g},{:.6g},{}\n", measured.wavenumber[s], measured.energy[s],
                           p.spectrum.energy(measured.wavenumber[s]), measured.modes[s]);
      if (!csv) throw std::runtime_error("writing " + stem + ".csv failed");
    });

    std::vector<double> prescribed;
    for (const double k : measured.wavenumber) prescribed.push_back(p.spectrum.energy(k));
    const render::Plot plot = spectrumPlot(fmt::format("wind {}: energy spectrum", i),
                                           {{"lattice (time slice 0)", measured.wavenumber, measured.energy, true},
                                            {"C_K eps^(2/3) k^(-5/3)", measured.wavenumber, prescribed, false}});
    if (plot.series.size() == 2) io::writePng(runDir / "winds" / (stem + ".png"), render::renderPlot(plot));

    json r = {{"speed_rms_mps", std::sqrt(meanSquare)},
              {"speed_rms_prescribed_mps", p.spectrum.speedRms()},
              {"divergence_over_gradient", div.gradientRms > 0.0 ? div.divergenceRms / div.gradientRms : 0.0},
              {"sweep_mps", lattice.sweep()}};
    try {
      const auto fit = turbulence::fitPowerLaw(measured, 1.5 * p.spectrum.lowWavenumber(), 0.7 * p.spectrum.highWavenumber());
      r["spectrum_exponent"] = fit.exponent;
      r["spectrum_shells_fitted"] = fit.points;
    } catch (const std::invalid_argument&) {
      r["spectrum_exponent"] = nullptr;  // too few shells in the inertial range to fit
    }
    out.push_back(r);
  }
  return json{{"winds", out}};
}

template json writeWindReports<2>(std::span<const turbulence::TurbulentWind<2>>, const fs::path&);
template json writeWindReports<3>(std::span<const turbulence::TurbulentWind<3>>, const fs::path&);

}  // namespace msim::scene
