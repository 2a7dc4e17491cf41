#pragma once
// Optimal reciprocal collision avoidance (van den Berg, Guy, Lin, Manocha, "Reciprocal n-body
// collision avoidance", ISRR 2011), the per-agent local planner the seed compares against
// (ch. 4.5.1: the RVO baseline failed past 70k agents; this one runs at 1M). Each ORCA agent takes
// the velocity closest to its preferred one that lies in its max-speed disc and in the
// half-planes ORCA_{i|j} of its nearest neighbours and of the nearby static obstacle edges.
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "msim/crowd/agents.hpp"
#include "msim/crowd/neighbour_grid.hpp"
#include "msim/crowd/obstacle_index.hpp"

namespace msim::crowd {

namespace lookahead {
struct DiscreteLookahead;
}

struct OrcaParams {
  float neighbourDist = 3.0f;    // agents farther than this (centre to centre) are ignored [m]
  int maxNeighbours = 10;        // only the closest ones within neighbourDist count
  float timeHorizon = 2.0f;      // tau: avoid collisions with agents within this time [s]
  float timeHorizonObst = 1.0f;  // tau for static obstacles [s]
};

// A velocity half-plane {v : (v - point) . normal >= 0}, normal of unit length.
struct HalfPlane {
  Vec2f point, normal;
};

// ORCA_{i|j} (sec. 5.1): the half-plane of velocities for agent i (velocity vi) that avoids,
// within the horizon 1 / invTau, a disc of combined radius r at relative position p moving with
// relative velocity v = v_i - v_j, taking `share` of the avoidance (1/2: reciprocal). Overlapping
// discs separate within 1 / invOverlap; `tie` (+-1) orders the normal when they coincide.
inline HalfPlane orcaHalfPlane(const Vec2f& p, const Vec2f& v, float r, float invTau, float invOverlap, const Vec2f& vi,
                               float share, float tie) {
  const float d2 = p.squaredNorm();
  Vec2f u, normal;  // u: from v to the closest point of the VO boundary; normal: outward there
  if (d2 > r * r) {
    // VO^tau: the cone from the origin tangent to the disc D(p, r), cut off by D(p/tau, r/tau).
    const Vec2f w = v - p * invTau;
    const float wp = w.dot(p);
    if (wp < 0.0f && wp * wp > r * r * w.squaredNorm()) {
      const float wLen = w.norm();  // closest boundary point on the cut-off arc
      normal = w / wLen;
      u = (r * invTau - wLen) * normal;
    } else {
      const float leg = std::sqrt(d2 - r * r);  // closest point on a leg of the cone
      if (p.x() * w.y() - p.y() * w.x() > 0.0f) {  // det(p, w) > 0: w left of p, the left leg
        const Vec2f dir = Vec2f(p.x() * leg - p.y() * r, p.x() * r + p.y() * leg) / d2;
        normal = Vec2f(-dir.y(), dir.x());
        u = v.dot(dir) * dir - v;
      } else {
        const Vec2f dir = Vec2f(p.x() * leg + p.y() * r, -p.x() * r + p.y() * leg) / d2;
        normal = Vec2f(dir.y(), -dir.x());
        u = v.dot(dir) * dir - v;
      }
    }
  } else {
    // Overlapping: the VO for the horizon 1 / invOverlap, D(p invOverlap, r invOverlap) (sec. 5.1).
    const Vec2f w = v - p * invOverlap;
    const float wLen = w.norm();
    normal = wLen > 1e-7f ? Vec2f(w / wLen) : Vec2f(tie, 0.0f);
    u = (r * invOverlap - wLen) * normal;
  }
  return {vi + share * u, normal};
}

// The incremental linear programs of the paper (sec. 5.2), exposed for testing. Velocity closest
// to `preferred` within |v| <= maxSpeed and all half-planes; when they have no common point, the
// velocity minimising the largest penetration into the half-planes after the first `hard` ones
// (the obstacle constraints, which stay strict). Deterministic: constraints in the given order.
Vec2f solveOrcaProgram(std::span<const HalfPlane> planes, std::size_t hard, const Vec2f& preferred, float maxSpeed,
                       std::vector<HalfPlane>& scratch);

class OrcaSolver {
 public:
  // New velocities of the agents whose model is Orca, written to out[i] (out.size() ==
  // agents.size(); other entries untouched), from the positions, last velocities and preferred
  // velocities in `agents`. dt is the coming time step: overlapping pairs aim to separate within
  // it (paper sec. 5.1). Parallel over agents; reads only old state, so the result does not depend
  // on the thread count. `obstacles` must have been built with reach >= the largest
  // maxSpeed * timeHorizonObst + radius. No allocation per agent (thread-local scratch).
  // With `lookahead` (Golas ch. 3.6) each agent also avoids the crowd as it will be at the
  // lookahead's horizons, in the same linear program. Agents flagged in `skip` (empty: none) are
  // left out (their out[i] untouched): the hybrid lookahead needs no ORCA answer for them.
  void computeVelocities(const Agents& agents, const StaticObstacles& obstacles, const OrcaParams& params, float dt,
                         std::span<Vec2f> out, const lookahead::DiscreteLookahead* lookahead = nullptr,
                         std::span<const std::uint8_t> skip = {});

 private:
  struct Neighbour {
    float d2;            // squared distance
    std::uint32_t id;    // agent index (ties are broken by it)
    std::uint32_t slot;  // cell-ordered slot
  };
  struct Scratch {
    std::vector<Neighbour> nearest;  // closest first
    std::vector<float> distances;    // squared distances to one row of stencil candidates
    std::vector<HalfPlane> planes;
    std::vector<HalfPlane> projected;
    std::vector<std::vector<HalfPlane>> far;  // a lookahead batch's far constraints, per agent
  };
  NeighbourGrid grid_;
  // Per-agent data gathered in the grid's cell order once per call, so neighbour reads are
  // contiguous (agents are stored in age order, which scatters neighbours over memory).
  struct Slot {
    Vec2f velocity;
    float radius;
    float share;  // 1/2 towards ORCA agents, 1 towards the others (they do not reciprocate)
  };
  std::vector<Slot> slots_;
  tbb::enumerable_thread_specific<Scratch> scratch_;
};

}  // namespace msim::crowd
