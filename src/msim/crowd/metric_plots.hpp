#pragma once
// Ready-made charts of crowd metrics (render::renderPlot): the speed-density diagram with
// Weidmann's curve, and time series such as agents in the scene or flow through a line.
#include <span>
#include <string>

#include "msim/crowd/fundamental_diagram.hpp"
#include "msim/render/plot.hpp"

namespace msim::crowd {

// Simulation samples as small markers, the non-empty bins as mean +- std with error bars, and
// Weidmann's v(rho) from 0.1 to rho_jam; density axis from 0 to max(rho_jam, densest sample),
// speed from 0.
render::Plot speedDensityPlot(std::span<const FdSample> samples, std::span<const FdBin> bins,
                              const WeidmannParams& weidmann = {});

// One line over time [s].
render::Plot timeSeriesPlot(const std::string& title, const std::string& yLabel, std::span<const double> times,
                            std::span<const double> values);

}  // namespace msim::crowd
