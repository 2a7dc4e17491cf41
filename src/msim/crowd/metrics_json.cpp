#include "msim/crowd/metrics_json.hpp"

#include <cmath>
#include <optional>

#include <nlohmann/json.hpp>

namespace msim::crowd {
namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
nlohmann::json number(const std::optional<double>& v) { return v ? number(*v) : nlohmann::json(nullptr); }

}  // namespace

nlohmann::json toJson(const SpeedStats& s) {
  return {{"count", s.count}, {"mean", s.mean},     {"stddev", s.stddev}, {"min", s.min}, {"p05", s.p05},
          {"p25", s.p25},     {"median", s.median}, {"p75", s.p75},       {"p95", s.p95}, {"max", s.max}};
}

nlohmann::json toJson(const NearestNeighbourFrame& f) {
  return {{"agents", f.agents},
          {"closer", f.closer},
          {"dense", f.dense},
          {"denseCloser", f.denseCloser},
          {"meanDenseRatio", number(f.meanDenseRatio())},
          {"fractionCloser", f.fractionCloser()},
          {"minRatio", number(f.minRatio)}};
}

nlohmann::json toJson(const NearestNeighbourAccumulator& a) {
  nlohmann::json j = toJson(a.total());
  j["frames"] = a.frames();
  return j;
}

nlohmann::json toJson(const AreaMeasurement& m) {
  return {{"area", m.area}, {"density", m.density}, {"speed", m.speed}};
}

nlohmann::json toJson(const MeasurementLine& line) {
  return {{"a", {line.a.x(), line.a.y()}}, {"b", {line.b.x(), line.b.y()}}};
}

nlohmann::json toJson(const LineCrossings& c) {
  return {{"positive", c.positive}, {"negative", c.negative}, {"net", c.net()}};
}

nlohmann::json toJson(const LineFlow& f) {
  return {{"crossings", toJson(f.crossings)},
          {"duration", f.duration},
          {"flow", f.flow},
          {"specificFlow", f.specificFlow}};
}

nlohmann::json toJson(const EvacuationTimes& t) {
  return {{"initial", t.initial}, {"left", t.left}, {"t50", number(t.t50)}, {"t90", number(t.t90)},
          {"t100", number(t.t100)}};
}

nlohmann::json toJson(const FdBin& b) {
  return {{"densityLo", b.densityLo}, {"densityHi", b.densityHi}, {"count", b.count},
          {"meanDensity", b.meanDensity}, {"meanSpeed", b.meanSpeed}, {"stdSpeed", b.stdSpeed}};
}

nlohmann::json toJson(std::span<const FdBin> bins) {
  nlohmann::json j = nlohmann::json::array();
  for (const FdBin& b : bins) j.push_back(toJson(b));
  return j;
}

nlohmann::json toJson(const WeidmannParams& p) {
  return {{"v0", p.v0}, {"gamma", p.gamma}, {"rhoJam", p.rhoJam}};
}

nlohmann::json toJson(const stress::SamplesByDensity& bins) {
  nlohmann::json j = nlohmann::json::array();
  for (std::size_t b = 0; b < bins.cells.size(); ++b) {
    const double cells = double(bins.cells[b]), agents = double(bins.agents[b]);
    if (cells == 0.0 && agents == 0.0) continue;
    const auto per = [](double sum, double count) { return count > 0.0 ? sum / count : 0.0; };
    j.push_back({{"density_from_per_m2", double(b) * bins.kBinWidth},
                 {"samples", bins.cells[b]},
                 {"turbulent_fraction", per(double(bins.turbulentCells[b]), cells)},
                 {"agent_samples", bins.agents[b]},
                 {"backward_fraction", per(double(bins.backward[b]), agents)},
                 {"rms_forward_mps", std::sqrt(per(bins.forward2[b], agents))},
                 {"rms_sideways_mps", std::sqrt(per(bins.sideways2[b], agents))}});
  }
  return j;
}

}  // namespace msim::crowd
