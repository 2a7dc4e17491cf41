#pragma once
// The "cloth" phenomenon: a mass-spring cloth (Selle ch. 5-6, solids/) falling onto bodies with
// friction (ch. 6.5). Keys and outputs: docs/cloth.md.
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType clothPhenomenonType();

}  // namespace msim::scene
