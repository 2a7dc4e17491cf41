#pragma once
// The "crowd" phenomenon: dense crowds with the unilateral incompressibility constraint
// (crowd/, Narain 2011 ch. 4), ORCA and scripted agents, wired to the scene keys of
// crowd_scene_keys.hpp. Per frame: agents as VDB points with the continuum's grids, a top-view PNG,
// trajectory rows; at the end trajectories.csv, a fundamental diagram and time-series plots, and
// the seed's validation numbers (nearest-neighbour distances) in run.json.
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType crowdPhenomenonType();

}  // namespace msim::scene
