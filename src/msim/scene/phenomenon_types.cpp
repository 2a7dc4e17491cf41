#include "msim/scene/crowd/crowd_phenomenon.hpp"
#include "msim/scene/gas/gas_phenomenon.hpp"
#include "msim/scene/granular/granular_phenomenon.hpp"
#include "msim/scene/liquid/liquid_phenomenon.hpp"
#include "msim/scene/solids/mass_spring_phenomenon.hpp"
#include "msim/scene/phenomenon.hpp"
#include "msim/scene/smoke/smoke_phenomenon.hpp"

namespace msim::scene {

const std::vector<PhenomenonType>& phenomenonTypes() {
  static const std::vector<PhenomenonType> types = {gasPhenomenonType(), smokePhenomenonType(), crowdPhenomenonType(),
                                                    granularPhenomenonType(), liquidPhenomenonType(), clothPhenomenonType(),
                                                    solidPhenomenonType()};
  return types;
}

const PhenomenonType* findPhenomenonType(const std::string& name) {
  for (const auto& t : phenomenonTypes())
    if (t.name == name) return &t;
  return nullptr;
}

}  // namespace msim::scene
