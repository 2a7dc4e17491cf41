#pragma once
// Standstill episodes of stop-and-go waves (Golas ch. 4.4, Fig. 4.3's vertical trajectory
// segments, the seed's check T11): an agent that wants to walk stands (slower than 0.05 m/s) for
// 1 s or more while the people ahead of it walk (the cells 1-3 m ahead along its preferred
// direction hold agents whose mean speed exceeds 0.2 m/s). A crowd that has stopped as a whole is
// jammed, not in a stop-and-go wave: its standstills are not counted.
#include <cstdint>
#include <vector>

#include "msim/core/grid_spec.hpp"
#include "msim/crowd/agents.hpp"

namespace msim::crowd::stress {

class StandstillDetector {
 public:
  static constexpr double kStandingSpeed = 0.05;  // [m/s]
  static constexpr double kMinimumDuration = 1.0; // [s]
  static constexpr double kMovingAhead = 0.2;     // [m/s]

  explicit StandstillDetector(const GridSpec<2>& grid);
  // One step of dt seconds; agents are identified by their stable ids.
  void sample(const Agents& agents, double dt);

  long episodes() const { return episodes_; }  // since the start
  long standing() const { return standing_; }  // agents in an episode now

 private:
  bool othersAheadMove(const Vec2f& x, const Vec2f& direction) const;

  GridSpec<2> grid_;
  std::vector<double> still_;     // per id: how long the agent has stood [s]
  std::vector<char> inEpisode_;   // per id: its standstill was counted
  std::vector<double> count_, speed_;  // per cell, built when a standstill reaches its duration
  long episodes_ = 0, standing_ = 0;
};

}  // namespace msim::crowd::stress
