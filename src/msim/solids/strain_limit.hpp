#pragma once
// Strain limiting (Provot 1995, as Bridson, Marino & Fedkiw 2003 use it for cloth): real cloth
// barely stretches, but springs soft enough for a large step let it sag like rubber. After a step,
// every spring stretched beyond the limit is shortened to it, its two ends moved along it in
// inverse proportion to their masses (pinned ends stay), symmetric Gauss-Seidel sweeps over the
// springs; the velocities take the change of position over the step, so momentum is kept.
// Compression is left alone (cloth buckles instead).
#include "msim/solids/mass_spring.hpp"

namespace msim::solids {

struct StrainLimitStats {
  int sweeps = 0;          // sweeps run
  double largest = 0.0;    // largest strain left [1]
};

// Limits every spring's strain to maxStrain (> 0) with up to `sweeps` symmetric Gauss-Seidel
// sweeps (fewer when none is over); dt > 0 is the step the positions came from.
StrainLimitStats limitStrain(MassSpringSystem& system, double maxStrain, int sweeps, double dt);

}  // namespace msim::solids
