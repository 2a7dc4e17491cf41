#pragma once
// Measurement lines and evacuation times, the two numbers egress studies report (e.g. the
// bottleneck experiments of Seyfried et al. 2009, Transportation Science 43: flow through a line
// in persons/s and specific flow in persons/(m s)).
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/crowd/agents.hpp"

namespace msim::crowd {

// The segment [a, b]. A crossing is positive when the agent moves to the right-hand side of the
// direction a -> b (along (b - a) rotated clockwise by 90 degrees), negative the other way.
struct MeasurementLine {
  Vec2 a = Vec2::Zero(), b = Vec2::UnitX();
  double length() const { return (b - a).norm(); }
};

struct LineCrossings {
  std::size_t positive = 0, negative = 0;
  long long net() const { return static_cast<long long>(positive) - static_cast<long long>(negative); }
};

// Crossings of the segments old[i] -> now[i] (the same agents, in the same order). A point exactly
// on the line counts as on its left side, and the line is half-open [a, b), so an agent that
// steps onto the line and back counts 0 and two lines that share an end point never count the same
// step twice. std::invalid_argument for mismatched sizes, non-finite data or a = b.
LineCrossings countCrossings(const MeasurementLine& line, std::span<const Vec2f> old, std::span<const Vec2f> now);
// The same for two frames of Agents, matching agents by id (ids ascending, as Agents keeps
// them); agents present in only one frame (spawned or removed) do not count.
LineCrossings countCrossings(const MeasurementLine& line, std::span<const std::uint64_t> oldIds,
                             std::span<const Vec2f> old, std::span<const std::uint64_t> nowIds,
                             std::span<const Vec2f> now);

struct LineFlow {
  LineCrossings crossings;
  double duration = 0.0;      // [s]
  double flow = 0.0;          // net crossings / duration [1/s]
  double specificFlow = 0.0;  // flow / line length [1/(m s)]
};

// Sums the crossings of consecutive frames of one line.
class FlowMeter {
 public:
  explicit FlowMeter(const MeasurementLine& line);
  // Crossings counted over a step of length dt > 0 [s]; returns that step's flow.
  LineFlow add(const LineCrossings& crossings, double dt);
  LineFlow total() const;
  const MeasurementLine& line() const { return line_; }

 private:
  LineFlow make(const LineCrossings& c, double duration) const;
  MeasurementLine line_;
  LineCrossings sum_;
  double duration_ = 0.0;
};

// Times at which 50%, 90% and 100% of the initial agents have left the scene.
struct EvacuationTimes {
  std::size_t initial = 0, left = 0;
  std::optional<double> t50, t90, t100;  // empty until reached [s]
};

// Fed with removal events; only agents present at the start count (inflow agents do not).
// "q of N have left" means at least ceil(q N) of them.
class EvacuationTimer {
 public:
  explicit EvacuationTimer(std::span<const std::uint64_t> initialIds);
  // Agent `id` left at `time`. Times must not decrease (std::invalid_argument); ids that are not
  // initial agents or were already recorded are ignored.
  void removed(double time, std::uint64_t id);
  const EvacuationTimes& times() const { return times_; }

 private:
  std::vector<std::uint64_t> ids_;  // sorted initial ids
  std::vector<std::uint8_t> gone_;
  double lastTime_ = -std::numeric_limits<double>::infinity();
  EvacuationTimes times_;
};

}  // namespace msim::crowd
