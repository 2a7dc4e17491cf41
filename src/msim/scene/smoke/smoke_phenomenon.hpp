#pragma once
// The "smoke" phenomenon: incompressible smoke and fire on a MAC grid (fluid/smoke; Selle ch. 2-3,
// Stam ch. 6.4.2-6.4.3), wired to scene keys smoke.*, fire.*, sources[], obstacles[].
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType smokePhenomenonType();

}  // namespace msim::scene
