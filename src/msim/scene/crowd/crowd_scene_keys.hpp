#pragma once
// Scene keys of the "crowd" phenomenon (crowd.*, goals[], obstacles[], groups[], inflows[],
// measurement_lines[]) and their translation into a ready-to-run crowd::CrowdSimulation setup,
// with errors that name the key.
#include <memory>
#include <string>
#include <vector>

#include "msim/crowd/crowd_simulation.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

struct CrowdMeasurementLine {
  std::string name;
  Vec2 from = Vec2::Zero(), to = Vec2::Zero();
};

struct CrowdSceneSetup {
  crowd::CrowdSettings settings;
  std::vector<crowd::Polygon> obstacles;        // static: planned around
  std::vector<crowd::MovingObstacle> moving;    // in motion: only avoided locally
  std::vector<crowd::Goal> goals;
  std::shared_ptr<const crowd::GlobalPlanner> planner;
  std::string plannerName;
  crowd::Agents agents;
  std::vector<crowd::Inflow> inflows;
  std::vector<crowd::Script> scripts;
  std::vector<CrowdMeasurementLine> lines;
  double maxStep = 0.1;    // [s]
  double gridCfl = 1.0;    // cells the fastest agent may cross per step
  double dMin = 0.5;       // 2 x the default agent radius [m]
  std::string colourBy = "speed";
  bool trajectories = true;
  std::size_t groupCount = 0;  // groups + inflows (agent colours by group)
  double denseFraction = 0.8;  // "densest regions" of the nearest-neighbour metric: rho >= this x rho_max
  double summariesFrom = 0.0;  // [s] the turbulence metrics' run-long summaries gather frames from here
};

void declareCrowdKeys(Schema& root);
// Throws InputError naming the scene file and key for any inconsistency.
CrowdSceneSetup buildCrowdScene(const Scene& scene);

}  // namespace msim::scene
