#include "msim/solids/strain_limit.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace msim::solids {

StrainLimitStats limitStrain(MassSpringSystem& system, double maxStrain, int sweeps, double dt) {
  if (!(maxStrain > 0.0) || !(dt > 0.0)) throw std::invalid_argument("strain limit: the limit and dt must be > 0");
  StrainLimitStats stats;
  auto correct = [&](const Spring& s) {
    const Vec3 d = system.x[s.b] - system.x[s.a];
    const double length = d.norm(), longest = (1.0 + maxStrain) * s.restLength;
    if (!(length > longest * (1.0 + 1e-9))) return false;
    const double wa = system.inverseMass(static_cast<std::size_t>(s.a)), wb = system.inverseMass(static_cast<std::size_t>(s.b));
    if (wa + wb == 0.0) return false;
    const Vec3 move = (length - longest) / (wa + wb) * (d / length);
    // The velocities take each move over the step as it is made (no copy of the positions).
    system.x[s.a] += wa * move;
    system.x[s.b] -= wb * move;
    system.v[s.a] += (wa / dt) * move;
    system.v[s.b] -= (wb / dt) * move;
    return true;
  };
  // Symmetric Gauss-Seidel: forwards, then backwards through the springs (one direction alone
  // drags a correction down a chain one spring per sweep).
  for (; stats.sweeps < sweeps; ++stats.sweeps) {
    bool over = false;
    for (const Spring& s : system.springs) over = correct(s) || over;
    for (auto s = system.springs.rbegin(); s != system.springs.rend(); ++s) over = correct(*s) || over;
    if (!over) break;
  }
  for (std::size_t s = 0; s < system.springs.size(); ++s) stats.largest = std::max(stats.largest, system.strain(s));
  return stats;
}

}  // namespace msim::solids
