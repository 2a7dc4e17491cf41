#include "msim/crowd/stress/standstill.hpp"

#include <algorithm>

namespace msim::crowd::stress {

StandstillDetector::StandstillDetector(const GridSpec<2>& grid) : grid_(grid) {}

bool StandstillDetector::othersAheadMove(const Vec2f& x, const Vec2f& direction) const {
  double n = 0.0, speed = 0.0;
  std::size_t last = grid_.cellCount();  // each cell once, though two samples may fall in it
  for (const float d : {1.0f, 2.0f, 3.0f}) {
    const Vec2f p = x + d * direction;
    if (!grid_.contains(p.cast<double>())) break;
    const std::size_t c = grid_.clampedCellIndex(p);
    if (c == last) continue;
    last = c;
    n += count_[c];
    speed += speed_[c];
  }
  return n > 0.0 && speed / n > kMovingAhead;
}

void StandstillDetector::sample(const Agents& a, double dt) {
  if (still_.size() < a.nextId) {  // ids are below nextId
    still_.resize(a.nextId, 0.0);
    inEpisode_.resize(a.nextId, 0);
  }
  bool binned = false;
  standing_ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::uint64_t id = a.id[i];
    const float wanted = a.preferredVelocity[i].norm();
    if (a.velocity[i].norm() >= kStandingSpeed || wanted < kStandingSpeed) {
      still_[id] = 0.0;
      inEpisode_[id] = 0;
      continue;
    }
    still_[id] += dt;
    if (inEpisode_[id]) {
      ++standing_;
      continue;
    }
    if (still_[id] < kMinimumDuration) continue;
    if (!binned) {  // the crowd's speeds per cell, once per step and only when needed
      count_.assign(grid_.cellCount(), 0.0);
      speed_.assign(grid_.cellCount(), 0.0);
      for (std::size_t k = 0; k < a.size(); ++k) {
        const std::size_t c = grid_.clampedCellIndex(a.position[k]);
        count_[c] += 1.0;
        speed_[c] += a.velocity[k].norm();
      }
      binned = true;
    }
    if (othersAheadMove(a.position[i], a.preferredVelocity[i] / wanted)) {
      inEpisode_[id] = 1;
      ++episodes_;
      ++standing_;
    }
  }
}

}  // namespace msim::crowd::stress
