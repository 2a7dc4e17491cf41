#include "msim/crowd/agents.hpp"

#include <algorithm>

namespace msim::crowd {

namespace {

// Reorders [begin, end) so that it is split at its middle position along `axis`: ascending, or
// descending when `descending`.
std::vector<Vec2>::iterator medianSplit(std::vector<Vec2>::iterator begin, std::vector<Vec2>::iterator end, int axis,
                                        bool descending) {
  const auto middle = begin + (end - begin) / 2;
  std::nth_element(begin, middle, end, [&](const Vec2& p, const Vec2& q) {
    return descending ? q[axis] < p[axis] : p[axis] < q[axis];
  });
  return middle;
}

// The median Hilbert sort: halve the points at the median along `first`, each half at its median
// along the other axis (in opposite directions), and visit the four quarters in the order of the
// Hilbert curve, recursing with the axes and directions the curve's turns give each quarter.
// Median splits adapt to any distribution of points and need no grid or bounding box.
void hilbertSort(std::vector<Vec2>::iterator begin, std::vector<Vec2>::iterator end, int first, bool reverseFirst,
                 bool reverseSecond) {
  if (end - begin <= 1) return;
  const int second = 1 - first;
  const auto half = medianSplit(begin, end, first, reverseFirst);
  const auto quarter = medianSplit(begin, half, second, reverseSecond);
  const auto threeQuarters = medianSplit(half, end, second, !reverseSecond);
  hilbertSort(begin, quarter, second, reverseSecond, reverseFirst);
  hilbertSort(quarter, half, first, reverseFirst, reverseSecond);
  hilbertSort(half, threeQuarters, first, reverseFirst, reverseSecond);
  hilbertSort(threeQuarters, end, second, !reverseSecond, !reverseFirst);
}

}  // namespace

void sortSpatially(std::vector<Vec2>& points) { hilbertSort(points.begin(), points.end(), 0, false, false); }

void Agents::reserve(std::size_t n) {
  position.reserve(n);
  velocity.reserve(n);
  preferredVelocity.reserve(n);
  radius.reserve(n);
  maxSpeed.reserve(n);
  goal.reserve(n);
  model.reserve(n);
  group.reserve(n);
  id.reserve(n);
}

std::size_t Agents::add(const AgentSpec& spec) {
  position.push_back(spec.position);
  velocity.push_back(Vec2f::Zero());
  preferredVelocity.push_back(Vec2f::Zero());
  radius.push_back(spec.radius);
  maxSpeed.push_back(spec.maxSpeed);
  goal.push_back(spec.goal);
  model.push_back(spec.model);
  group.push_back(spec.group);
  id.push_back(nextId++);
  return position.size() - 1;
}

void Agents::removeFlagged(const std::vector<std::uint8_t>& remove) {
  compactFlagged(position, remove);
  compactFlagged(velocity, remove);
  compactFlagged(preferredVelocity, remove);
  compactFlagged(radius, remove);
  compactFlagged(maxSpeed, remove);
  compactFlagged(goal, remove);
  compactFlagged(model, remove);
  compactFlagged(group, remove);
  compactFlagged(id, remove);
}

AgentSpec Agents::spec(std::size_t i) const {
  return AgentSpec{position[i], radius[i], maxSpeed[i], goal[i], model[i], group[i]};
}

}  // namespace msim::crowd
