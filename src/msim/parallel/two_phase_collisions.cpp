#include "msim/parallel/two_phase_collisions.hpp"

#include <algorithm>
#include <numeric>

#include "msim/parallel/mpi_session.hpp"

namespace msim::parallel {

namespace {

// Union-find over nodes, joining the nodes of each boundary item.
struct NodeSets {
  std::vector<int> parent;
  explicit NodeSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int root(int i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  }
  void join(int a, int b) {
    a = root(a), b = root(b);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace

std::vector<int> TwoPhaseSchedule::serialOrder() const {
  std::vector<int> order;
  for (const auto& c : components) order.insert(order.end(), c.begin(), c.end());
  for (const auto& r : internal) order.insert(order.end(), r.begin(), r.end());
  return order;
}

TwoPhaseSchedule twoPhaseSchedule(const std::vector<CollisionItem>& items, const std::vector<int>& owner, int ranks) {
  TwoPhaseSchedule s;
  s.internal.resize(static_cast<std::size_t>(ranks));
  NodeSets sets(owner.size());
  std::vector<int> boundary;
  for (std::size_t k = 0; k < items.size(); ++k) {
    int first = -1;
    bool spans = false;
    for (int node : items[k]) {
      if (node < 0) continue;
      const int o = owner[static_cast<std::size_t>(node)];
      if (first < 0) first = o;
      spans = spans || o != first;
    }
    if (first < 0) continue;  // an item with no node does nothing
    if (!spans) {
      s.internal[static_cast<std::size_t>(first)].push_back(static_cast<int>(k));
      continue;
    }
    boundary.push_back(static_cast<int>(k));
    int anchor = -1;
    for (int node : items[k])
      if (node >= 0) {
        if (anchor >= 0) sets.join(anchor, node);
        anchor = node;
      }
  }
  // Components in the order of their first item; the lowest owner among their nodes runs them.
  std::vector<int> componentOf(owner.size(), -1);
  for (int k : boundary) {
    int node = -1;
    for (int n : items[static_cast<std::size_t>(k)])
      if (n >= 0) node = n;
    const int root = sets.root(node);
    int& c = componentOf[static_cast<std::size_t>(root)];
    if (c < 0) {
      c = static_cast<int>(s.components.size());
      s.components.emplace_back();
      s.componentRank.push_back(ranks);
    }
    s.components[static_cast<std::size_t>(c)].push_back(k);
    for (int n : items[static_cast<std::size_t>(k)])
      if (n >= 0) s.componentRank[static_cast<std::size_t>(c)] = std::min(s.componentRank[static_cast<std::size_t>(c)], owner[static_cast<std::size_t>(n)]);
  }
  return s;
}

std::vector<int> nodesOf(const std::vector<CollisionItem>& items, const std::vector<int>& which) {
  std::vector<int> nodes;
  for (int k : which)
    for (int n : items[static_cast<std::size_t>(k)])
      if (n >= 0) nodes.push_back(n);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

void shareVelocities(const std::vector<int>& nodes, std::vector<Vec3>& v, MPI_Comm comm) {
  // Rows of (node, vx, vy, vz) in doubles: node indices below 2^53 are exact.
  std::vector<double> rows;
  rows.reserve(4 * nodes.size());
  for (int n : nodes) {
    const Vec3& x = v[static_cast<std::size_t>(n)];
    rows.insert(rows.end(), {double(n), x[0], x[1], x[2]});
  }
  const std::vector<double> all = joinedFromAll(rows, comm);
  for (std::size_t at = 0; at < all.size(); at += 4)
    v[static_cast<std::size_t>(all[at])] = Vec3(all[at + 1], all[at + 2], all[at + 3]);
}

}  // namespace msim::parallel
