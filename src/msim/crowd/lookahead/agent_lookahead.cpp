#include "msim/crowd/lookahead/agent_lookahead.hpp"

#include <algorithm>
#include <cmath>

#include "msim/core/parallel.hpp"
#include "msim/crowd/lookahead/curtailing.hpp"

namespace msim::crowd::lookahead {

namespace {

float cross(const Vec2f& a, const Vec2f& b) { return a.x() * b.y() - a.y() * b.x(); }

// How far along the ray from x in direction d (unit) the first obstacle edge lies, up to `length`.
float clearDistance(const StaticObstacles& obstacles, const Vec2f& x, const Vec2f& d, float length) {
  float clear = length;
  if (obstacles.empty()) return clear;
  // Edges near points every `reach` along the ray: a superset of the edges the ray crosses. An
  // edge the ray crosses at t is near the point within half a stride of t, so once a crossing is
  // known the points beyond it by more than a stride find none closer.
  const float stride = std::max(obstacles.reach(), 1e-3f);
  for (float s = 0.0f; s <= clear + stride; s += stride) {
    obstacles.forEachEdgeNear(x + std::min(s, length) * d, [&](const Vec2f& a, const Vec2f& b) {
      const Vec2f e = b - a;
      const float denom = cross(d, e);
      if (std::abs(denom) < 1e-9f) return;
      const float t = cross(a - x, e) / denom, u = cross(a - x, d) / denom;
      if (t >= 0.0f && u >= 0.0f && u <= 1.0f) clear = std::min(clear, t);
    });
  }
  return clear;
}

}  // namespace

void AgentLookahead::resize(std::size_t agents) {
  moments_.resize(agents);
  walked_.resize(agents, 0);
}

void AgentLookahead::removeFlagged(const std::vector<std::uint8_t>& remove) {
  compactFlagged(moments_, remove);
  compactFlagged(walked_, remove);
}

void AgentLookahead::record(std::span<const Vec2f> previous, std::span<const Vec2f> current, double dt) {
  resize(current.size());
  // Weights halve every tau_w / 2.
  const double forget = std::exp(-std::log(2.0) * dt / (0.5 * settings_.metricWindow));
  parallelFor(0, current.size(), [&](std::size_t i) {
    if (!walked_[i]) {
      walked_[i] = 1;
      return;
    }
    moments_[i].scale(forget);
    moments_[i].add(((current[i] - previous[i]) / static_cast<float>(dt)).cast<double>());
  });
}

void AgentLookahead::localInconsistency(const Agents& agents, double cell, std::vector<DeviationMoment>& cells,
                                        std::vector<float>& sigma) const {
  const std::size_t n = agents.size();
  sigma.resize(n);
  if (n == 0) return;
  Vec2f lo = agents.position.front(), hi = lo;
  for (const Vec2f& x : agents.position) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const float size = static_cast<float>(cell);
  const int nx = static_cast<int>((hi.x() - lo.x()) / size) + 1, ny = static_cast<int>((hi.y() - lo.y()) / size) + 1;
  cells.assign(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), DeviationMoment());
  const auto cellOf = [&](const Vec2f& x, int& cx, int& cy) {
    cx = std::min(nx - 1, static_cast<int>((x.x() - lo.x()) / size));
    cy = std::min(ny - 1, static_cast<int>((x.y() - lo.y()) / size));
  };
  for (std::size_t i = 0; i < n; ++i) {
    int cx = 0, cy = 0;
    cellOf(agents.position[i], cx, cy);
    if (i < moments_.size())
      cells[static_cast<std::size_t>(cy) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(cx)].add(moments_[i]);
  }
  parallelFor(0, n, [&](std::size_t i) {
    int cx = 0, cy = 0;
    cellOf(agents.position[i], cx, cy);
    DeviationMoment pooled;
    for (int y = std::max(0, cy - 1); y <= std::min(ny - 1, cy + 1); ++y)
      for (int x = std::max(0, cx - 1); x <= std::min(nx - 1, cx + 1); ++x)
        pooled.add(cells[static_cast<std::size_t>(y) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(x)]);
    sigma[i] = static_cast<float>(pooled.sigma(settings_.metricMode));
  });
}

const DiscreteLookahead& AgentLookahead::prepare(const Agents& agents, const StaticObstacles& obstacles,
                                                 double neighbourDist, double maxSpeed, const Vec2& lo, const Vec2& hi,
                                                 const Needs& needs) {
  const std::size_t n = agents.size();
  resize(n);
  lookahead_.schedule = HorizonSchedule{settings_.baseStep, settings_.levels, settings_.coarsening, neighbourDist, maxSpeed};
  lookahead_.tabulate();
  depth_.assign(n, 0);
  if (n > 0) {
    localInconsistency(agents, neighbourDist, cells_, sigma_);
    const HorizonSchedule& s = lookahead_.schedule;
    parallelFor(0, n, [&](std::size_t i) {
      if (agents.model[i] == AgentModel::Scripted) return;
      int depth = depthForInconsistency(sigma_[i], settings_.sigmaMax, s.levels);
      const float speed = agents.velocity[i].norm();
      if (depth > 0 && speed > 1e-6f) {
        const float reach = speed * static_cast<float>(s.horizon(depth));
        const float clear = clearDistance(obstacles, agents.position[i], agents.velocity[i] / speed, reach);
        if (clear < reach) depth = std::min(depth, depthForObstacle(speed, clear, s));
      }
      depth_[i] = static_cast<std::uint8_t>(depth);
    });
  }
  if (needs.tree) lookahead_.tree.build(agents.position, agents.velocity, agents.radius);
  if (needs.densities.now || needs.densities.far)
    future_.build(lookahead_.schedule, settings_.cell, lo, hi, agents.position, agents.velocity, needs.densities);
  lookahead_.positions = agents.position;
  lookahead_.velocities = agents.velocity;
  lookahead_.radii = agents.radius;
  lookahead_.depth = depth_;
  return lookahead_;
}

double AgentLookahead::sceneInconsistency() const {
  DeviationMoment pooled;
  for (const DeviationMoment& m : moments_) pooled.add(m);
  return pooled.sigma(settings_.metricMode);
}

}  // namespace msim::crowd::lookahead
