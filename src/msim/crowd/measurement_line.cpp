#include "msim/crowd/measurement_line.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace msim::crowd {
namespace {

void requireLine(const MeasurementLine& line) {
  if (!line.a.allFinite() || !line.b.allFinite() || line.a == line.b)
    throw std::invalid_argument("measurement line: the end points must be finite and distinct");
}

// +1, -1 or 0 for the step p -> q across the line.
int crossing(const MeasurementLine& line, const Vec2f& pf, const Vec2f& qf) {
  if (!pf.allFinite() || !qf.allFinite()) throw std::invalid_argument("countCrossings: non-finite position");
  const Vec2 p = pf.cast<double>(), q = qf.cast<double>();
  const Vec2 d = line.b - line.a;
  const Vec2 normal(d.y(), -d.x());  // points to the right of a -> b
  const double sp = normal.dot(p - line.a), sq = normal.dot(q - line.a);
  const bool rightBefore = sp > 0.0, rightAfter = sq > 0.0;
  if (rightBefore == rightAfter) return 0;
  // Where the step meets the line, as a fraction u of the way from a to b.
  const Vec2 x = p + (sp / (sp - sq)) * (q - p);
  const double u = (x - line.a).dot(d) / d.squaredNorm();
  if (u < 0.0 || u >= 1.0) return 0;
  return rightAfter ? 1 : -1;
}

void add(LineCrossings& c, int s) {
  if (s > 0) ++c.positive;
  if (s < 0) ++c.negative;
}

}  // namespace

LineCrossings countCrossings(const MeasurementLine& line, std::span<const Vec2f> old, std::span<const Vec2f> now) {
  requireLine(line);
  if (old.size() != now.size()) throw std::invalid_argument("countCrossings: old and new positions differ in size");
  LineCrossings c;
  for (std::size_t i = 0; i < old.size(); ++i) add(c, crossing(line, old[i], now[i]));
  return c;
}

LineCrossings countCrossings(const MeasurementLine& line, std::span<const std::uint64_t> oldIds,
                             std::span<const Vec2f> old, std::span<const std::uint64_t> nowIds,
                             std::span<const Vec2f> now) {
  requireLine(line);
  if (oldIds.size() != old.size() || nowIds.size() != now.size())
    throw std::invalid_argument("countCrossings: one id per position");
  if (!std::is_sorted(oldIds.begin(), oldIds.end()) || !std::is_sorted(nowIds.begin(), nowIds.end()))
    throw std::invalid_argument("countCrossings: ids must be ascending");
  LineCrossings c;
  // Merge of two sorted id lists: agents in both frames are the ones that moved.
  for (std::size_t i = 0, j = 0; i < oldIds.size() && j < nowIds.size();) {
    if (oldIds[i] < nowIds[j]) {
      ++i;
    } else if (nowIds[j] < oldIds[i]) {
      ++j;
    } else {
      add(c, crossing(line, old[i++], now[j++]));
    }
  }
  return c;
}

FlowMeter::FlowMeter(const MeasurementLine& line) : line_(line) { requireLine(line); }

LineFlow FlowMeter::make(const LineCrossings& c, double duration) const {
  LineFlow f;
  f.crossings = c;
  f.duration = duration;
  f.flow = duration > 0.0 ? static_cast<double>(c.net()) / duration : 0.0;
  f.specificFlow = f.flow / line_.length();
  return f;
}

LineFlow FlowMeter::add(const LineCrossings& crossings, double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("FlowMeter::add: dt must be > 0");
  sum_.positive += crossings.positive;
  sum_.negative += crossings.negative;
  duration_ += dt;
  return make(crossings, dt);
}

LineFlow FlowMeter::total() const { return make(sum_, duration_); }

EvacuationTimer::EvacuationTimer(std::span<const std::uint64_t> initialIds)
    : ids_(initialIds.begin(), initialIds.end()) {
  std::sort(ids_.begin(), ids_.end());
  ids_.erase(std::unique(ids_.begin(), ids_.end()), ids_.end());
  gone_.assign(ids_.size(), 0);
  times_.initial = ids_.size();
}

void EvacuationTimer::removed(double time, std::uint64_t id) {
  if (!std::isfinite(time) || time < lastTime_)
    throw std::invalid_argument("EvacuationTimer::removed: times must be finite and non-decreasing");
  lastTime_ = time;
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), id);
  if (it == ids_.end() || *it != id) return;
  std::uint8_t& gone = gone_[static_cast<std::size_t>(it - ids_.begin())];
  if (gone) return;
  gone = 1;
  ++times_.left;
  // Integer thresholds ceil(q N), computed exactly: (q N) = (num N) / 10.
  const auto reached = [&](std::size_t tenths) { return times_.left * 10 >= tenths * times_.initial; };
  if (!times_.t50 && reached(5)) times_.t50 = time;
  if (!times_.t90 && reached(9)) times_.t90 = time;
  if (!times_.t100 && reached(10)) times_.t100 = time;
}

}  // namespace msim::crowd
