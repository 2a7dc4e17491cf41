#pragma once
// How deep an agent looks ahead (Golas ch. 3.7-3.8): full depth i_max where its neighbourhood
// moves consistently, falling linearly with the inconsistency metric to 0 (plain local avoidance)
// at sigma_max, and no deeper than the levels whose extrapolated positions it can see without an
// obstacle in between. Eq. 3.10 read literally allows more levels at higher sigma, against the
// chapter's prose; this follows the prose: L(sigma) = clamp(i_max - floor(sigma i_max / sigma_max),
// 0, i_max).
#include "msim/crowd/lookahead/horizons.hpp"

namespace msim::crowd::lookahead {

// L(sigma) for sigma >= 0; sigmaMax = infinity keeps the full depth (constant lookahead).
int depthForInconsistency(double sigma, double sigmaMax, int levels);

// The deepest level i whose extrapolation x + v dt_i stays short of an obstacle `clearDistance`
// ahead along the agent's velocity: the largest i with speed dt_i < clearDistance (0 when even
// the first level's reaches it). The levels' segments are nested, so all beyond it are blocked too.
int depthForObstacle(double speed, double clearDistance, const HorizonSchedule& schedule);

}  // namespace msim::crowd::lookahead
