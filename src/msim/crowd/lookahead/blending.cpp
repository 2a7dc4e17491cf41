#include "msim/crowd/lookahead/blending.hpp"

#include <algorithm>

namespace msim::crowd::lookahead {

double densityWeight(double density, const BlendThresholds& t) {
  return std::clamp((density - t.continuumFrom) / (t.discreteUpTo - t.continuumFrom), 0.0, 1.0);
}

double varianceWeight(double speedDeviation, double meanSpeed, const BlendThresholds& t) {
  if (meanSpeed < t.stillSpeed) return speedDeviation < t.stillSpeed ? 1.0 : 0.0;
  return std::clamp((t.disorderedFrom * meanSpeed - speedDeviation) / ((t.disorderedFrom - t.uniformBelow) * meanSpeed), 0.0,
                    1.0);
}

double blendWeight(double density, double speedDeviation, double meanSpeed, const BlendThresholds& t) {
  return densityWeight(density, t) * varianceWeight(speedDeviation, meanSpeed, t);
}

}  // namespace msim::crowd::lookahead
