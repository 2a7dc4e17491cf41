#pragma once
// The discrete crowd (Narain 2011, ch. 4.3): agents stored as a structure of arrays so the
// per-agent passes (splatting, sampling, neighbour search, integration) stream through memory.
// Positions and velocities are single precision, which is what the grid transfers take
// (msim::Splatter) and plenty for scenes up to kilometres across (6e-5 m resolution at 1 km).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::crowd {

using Vec2f = Vecf<2>;

// How an agent chooses its velocity each step.
enum class AgentModel : std::uint8_t {
  Uic,       // continuum: preferred velocity projected by the UIC (ch. 4.4), eq. 4.3
  Orca,      // optimal reciprocal collision avoidance (van den Berg et al. 2011)
  Scripted,  // follows its own script; an obstacle to everybody else (ch. 4.4.3)
};

struct AgentSpec {
  Vec2f position = Vec2f::Zero();  // [m]
  float radius = 0.25f;            // [m]; d_min between two agents is the sum of their radii
  float maxSpeed = 1.4f;           // [m/s]
  std::uint32_t goal = 0;          // index into the scene's goals
  AgentModel model = AgentModel::Uic;
  std::uint32_t group = 0;         // user label (inflow, spawn region), for metrics and colours
};

// Orders points along a Hilbert curve (median splits), so that agents added in this order
// are stored next to their neighbours: the per-agent passes of a step (splat, gather, collision
// buckets) then read memory nearly in order instead of at random. Agents placed at random get
// their ids in this order; it lasts as long as neighbours stay neighbours.
void sortSpatially(std::vector<Vec2>& points);

// Drops the entries of `v` flagged in `remove` (one flag per agent; entries past its end are
// kept), keeping the order: per-agent state that must follow Agents::removeFlagged.
template <typename T>
void compactFlagged(std::vector<T>& v, const std::vector<std::uint8_t>& remove) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (i >= remove.size() || !remove[i]) v[out++] = v[i];
  v.resize(out);
}

class Agents {
 public:
  std::size_t size() const { return position.size(); }
  bool empty() const { return position.empty(); }
  void reserve(std::size_t n);
  // Appends an agent with velocity 0 and a fresh id; returns its index.
  std::size_t add(const AgentSpec& spec);
  // Removes the agents whose flag is non-zero (remove.size() == size()), keeping the order of the
  // rest, so that indices stay sorted by age and outputs stay reproducible.
  void removeFlagged(const std::vector<std::uint8_t>& remove);
  AgentSpec spec(std::size_t i) const;

  std::vector<Vec2f> position;           // x_i [m]
  std::vector<Vec2f> velocity;           // v_i, the velocity of the last step [m/s]
  std::vector<Vec2f> preferredVelocity;  // v~_i from the planner [m/s]
  std::vector<float> radius;             // [m]
  std::vector<float> maxSpeed;           // [m/s]
  std::vector<std::uint32_t> goal;
  std::vector<AgentModel> model;
  std::vector<std::uint32_t> group;
  std::vector<std::uint64_t> id;         // stable over the run, never reused
  std::uint64_t nextId = 0;
};

}  // namespace msim::crowd
