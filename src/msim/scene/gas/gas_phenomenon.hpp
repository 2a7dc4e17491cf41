#pragma once
// The "gas" phenomenon: Stam's density and temperature in analytic motion fields (fluid/gas),
// wired to scene keys: gas.*, motion_fields[], sources[], obstacles[].
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType gasPhenomenonType();

}  // namespace msim::scene
