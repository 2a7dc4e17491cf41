#pragma once
// Wall-clock accounting per named stage of a run ("advect", "project", "write"...), for the
// end-of-run summary and the run report. A ScopedStage measures one call of a stage and adds it
// when it goes out of scope. Adding takes a mutex: meant for stage granularity (a few calls per
// step), not inner loops. Percentages are of the sum over all stages, so they add up to 100 when
// stages do not nest.
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

namespace msim {

struct StageTime {
  std::string name;
  double seconds = 0.0;     // total wall time
  std::uint64_t calls = 0;  // number of measured calls
  double percent = 0.0;     // share of the sum over all stages
};

class StageTimers {
 public:
  void add(std::string_view stage, double seconds);
  // Adds every stage of `other` (its seconds and calls) under prefix + its name, e.g. a solver's
  // own stages into a run's table.
  void merge(const StageTimers& other, std::string_view prefix = {});
  // One row per stage, in the order the stages were first used.
  std::vector<StageTime> table() const;
  double totalSeconds() const;
  // Aligned text table with a total line, for the end-of-run summary.
  std::string formatTable() const;
  void reset();

 private:
  struct Entry {
    std::string name;
    double seconds = 0.0;
    std::uint64_t calls = 0;
  };
  Entry& entry(std::string_view stage);  // found or appended; the caller holds mutex_
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;  // a handful of stages: a linear search beats hashing
};

class ScopedStage {
 public:
  ScopedStage(StageTimers& timers, std::string_view stage)
      : timers_(timers), stage_(stage), start_(std::chrono::steady_clock::now()) {}
  ~ScopedStage() { timers_.add(stage_, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count()); }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  StageTimers& timers_;
  std::string_view stage_;  // callers pass names that outlive the scope (usually literals)
  std::chrono::steady_clock::time_point start_;
};

// Adds the wall time of its scope to a plain counter (per-solver statistics that are not stages).
class ScopedTimer {
 public:
  explicit ScopedTimer(double& seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  ~ScopedTimer() { seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double& seconds_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace msim
