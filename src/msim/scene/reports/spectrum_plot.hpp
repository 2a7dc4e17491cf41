#pragma once
// Energy spectra as log-log PNG charts (log10 k against log10 E: the plot module has linear axes),
// shared by the wind reports of runs and by `msim spectrum`.
#include <string>
#include <vector>

#include "msim/render/plot.hpp"

namespace msim::scene {

struct SpectrumCurve {
  std::string name;
  std::vector<double> wavenumber, energy;  // [rad/m], [m^3/s^2]; non-positive energies are skipped
  bool markers = false;                    // markers (measured) or a line (prescribed)
};

// Curves below 1e-9 of the largest energy shown are left out (shells holding only round-off).
render::Plot spectrumPlot(const std::string& title, const std::vector<SpectrumCurve>& curves);

}  // namespace msim::scene
