#include "msim/core/timer.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace msim {

StageTimers::Entry& StageTimers::entry(std::string_view stage) {
  auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == stage; });
  if (it == entries_.end()) it = entries_.insert(entries_.end(), Entry{std::string(stage), 0.0, 0});
  return *it;
}

void StageTimers::add(std::string_view stage, double seconds) {
  std::lock_guard lock(mutex_);
  Entry& e = entry(stage);
  e.seconds += seconds;
  ++e.calls;
}

void StageTimers::merge(const StageTimers& other, std::string_view prefix) {
  if (&other == this) throw std::invalid_argument("StageTimers::merge: a table cannot merge itself");
  const std::vector<StageTime> stages = other.table();
  std::lock_guard lock(mutex_);
  for (const StageTime& t : stages) {
    Entry& e = entry(std::string(prefix) + t.name);
    e.seconds += t.seconds;
    e.calls += t.calls;
  }
}

double StageTimers::totalSeconds() const {
  std::lock_guard lock(mutex_);
  double total = 0.0;
  for (const Entry& e : entries_) total += e.seconds;
  return total;
}

std::vector<StageTime> StageTimers::table() const {
  std::lock_guard lock(mutex_);
  double total = 0.0;
  for (const Entry& e : entries_) total += e.seconds;
  std::vector<StageTime> rows;
  rows.reserve(entries_.size());
  for (const Entry& e : entries_)
    rows.push_back({e.name, e.seconds, e.calls, total > 0.0 ? 100.0 * e.seconds / total : 0.0});
  return rows;
}

std::string StageTimers::formatTable() const {
  const std::vector<StageTime> rows = table();
  std::size_t width = 5;  // "stage" / "total"
  for (const StageTime& r : rows) width = std::max(width, r.name.size());
  std::string out = fmt::format("{:<{}}  {:>10}  {:>8}  {:>6}\n", "stage", width, "seconds", "calls", "%");
  double total = 0.0;
  for (const StageTime& r : rows) {
    out += fmt::format("{:<{}}  {:>10.3f}  {:>8}  {:>6.1f}\n", r.name, width, r.seconds, r.calls, r.percent);
    total += r.seconds;
  }
  out += fmt::format("{:<{}}  {:>10.3f}  {:>8}  {:>6.1f}\n", "total", width, total, "", rows.empty() ? 0.0 : 100.0);
  return out;
}

void StageTimers::reset() {
  std::lock_guard lock(mutex_);
  entries_.clear();
}

}  // namespace msim
