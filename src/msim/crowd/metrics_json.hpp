#pragma once
// The crowd metrics as JSON for run.json. Non-finite numbers (an agent without a neighbour, a
// time not reached yet) become null, which is what nlohmann::json writes for them anyway.
#include <span>

#include <nlohmann/json_fwd.hpp>

#include "msim/crowd/fundamental_diagram.hpp"
#include "msim/crowd/measurement_line.hpp"
#include "msim/crowd/metrics.hpp"
#include "msim/crowd/stress/turbulence_metrics.hpp"
#include "msim/crowd/voronoi_density.hpp"

namespace msim::crowd {

nlohmann::json toJson(const SpeedStats& stats);
// Includes the derived meanDenseRatio (in units of d_min) and fractionCloser.
nlohmann::json toJson(const NearestNeighbourFrame& frame);
nlohmann::json toJson(const NearestNeighbourAccumulator& accumulator);
nlohmann::json toJson(const AreaMeasurement& measurement);
nlohmann::json toJson(const MeasurementLine& line);
nlohmann::json toJson(const LineCrossings& crossings);
nlohmann::json toJson(const LineFlow& flow);
nlohmann::json toJson(const EvacuationTimes& times);
nlohmann::json toJson(const FdBin& bin);
nlohmann::json toJson(std::span<const FdBin> bins);
nlohmann::json toJson(const WeidmannParams& params);
// The bins that hold samples: the share of crowd cells over the turbulent pressure, of agents
// moving away from their goal, and the agents' rms forward and sideways speeds.
nlohmann::json toJson(const stress::SamplesByDensity& bins);

}  // namespace msim::crowd
