#include "msim/scene/reports/spectrum_plot.hpp"

#include <algorithm>
#include <cmath>

namespace msim::scene {

render::Plot spectrumPlot(const std::string& title, const std::vector<SpectrumCurve>& curves) {
  render::Plot plot;
  plot.title = title;
  plot.xLabel = "log10 k (rad/m)";
  plot.yLabel = "log10 E (m^3/s^2)";
  double peak = 0.0;
  for (const auto& c : curves)
    for (const double e : c.energy) peak = std::max(peak, e);
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const SpectrumCurve& c = curves[i];
    render::PlotSeries s;
    s.name = c.name;
    s.colour = render::plotColour(static_cast<int>(i));
    s.line = !c.markers;
    s.markers = c.markers;
    s.lineWidth = c.markers ? 1 : 2;
    for (std::size_t k = 0; k < c.wavenumber.size(); ++k) {
      if (!(c.energy[k] > 1e-9 * peak) || !(c.wavenumber[k] > 0.0)) continue;
      s.x.push_back(std::log10(c.wavenumber[k]));
      s.y.push_back(std::log10(c.energy[k]));
    }
    if (!s.x.empty()) plot.series.push_back(s);
  }
  return plot;
}

}  // namespace msim::scene
