#include "msim/crowd/lookahead/curtailing.hpp"

#include <algorithm>
#include <cmath>

namespace msim::crowd::lookahead {

int depthForInconsistency(double sigma, double sigmaMax, int levels) {
  if (!std::isfinite(sigmaMax)) return levels;
  if (!(sigmaMax > 0.0)) return 0;
  const double steps = std::floor(std::max(0.0, sigma) * levels / sigmaMax);
  return static_cast<int>(std::clamp(levels - steps, 0.0, static_cast<double>(levels)));
}

int depthForObstacle(double speed, double clearDistance, const HorizonSchedule& schedule) {
  int depth = 0;
  for (int i = 1; i <= schedule.levels && speed * schedule.horizon(i) < clearDistance; ++i) depth = i;
  return depth;
}

}  // namespace msim::crowd::lookahead
