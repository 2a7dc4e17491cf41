#include "msim/crowd/metric_plots.hpp"

#include <algorithm>

namespace msim::crowd {
namespace {

render::PlotSeries series(const std::string& name, int colour) {
  render::PlotSeries s;
  s.name = name;
  s.colour = render::plotColour(colour);
  return s;
}

}  // namespace

render::Plot speedDensityPlot(std::span<const FdSample> samples, std::span<const FdBin> bins,
                              const WeidmannParams& weidmann) {
  render::Plot plot;
  plot.title = "Speed-density relation";
  plot.xLabel = "density (1/m^2)";
  plot.yLabel = "speed (m/s)";
  plot.xMin = 0.0;
  plot.yMin = 0.0;

  render::PlotSeries sim = series("simulation", 4);
  sim.line = false;
  sim.markers = true;
  sim.markerRadius = 1;
  double densest = weidmann.rhoJam;
  for (const FdSample& s : samples) {
    sim.x.push_back(s.density);
    sim.y.push_back(s.speed);
    densest = std::max(densest, s.density);
  }
  plot.xMax = densest;

  render::PlotSeries binned = series("binned mean +- std", 0);
  binned.markers = true;
  binned.markerRadius = 3;
  binned.lineWidth = 2;
  for (const FdBin& b : bins)
    if (b.count > 0) {
      binned.x.push_back(b.meanDensity);
      binned.y.push_back(b.meanSpeed);
      binned.yError.push_back(b.stdSpeed);
    }

  // Weidmann's curve has its steep part at low density, so sample densely there.
  render::PlotSeries curve = series("Weidmann 1993", 1);
  curve.lineWidth = 2;
  const int n = 200;
  for (int k = 0; k <= n; ++k) {
    const double rho = 0.1 + (weidmann.rhoJam - 0.1) * k / n;
    curve.x.push_back(rho);
    curve.y.push_back(weidmannSpeed(rho, weidmann));
  }
  plot.series = {std::move(sim), std::move(binned), std::move(curve)};
  return plot;
}

render::Plot timeSeriesPlot(const std::string& title, const std::string& yLabel, std::span<const double> times,
                            std::span<const double> values) {
  render::Plot plot;
  plot.title = title;
  plot.xLabel = "time (s)";
  plot.yLabel = yLabel;
  plot.legend = false;
  render::PlotSeries s = series(yLabel, 0);
  s.lineWidth = 2;
  s.x.assign(times.begin(), times.end());
  s.y.assign(values.begin(), values.end());
  plot.series.push_back(std::move(s));
  return plot;
}

}  // namespace msim::crowd
