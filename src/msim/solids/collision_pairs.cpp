#include "msim/solids/collision_pairs.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"

namespace msim::solids {

namespace {

// Refitted trees are rebuilt after this many queries: a crumpling cloth moves its triangles far
// from where the tree's split planes were chosen, and refitted boxes then overlap more and more.
constexpr int kQueriesPerRebuild = 16;

bool sharesVertex(const std::array<int, 2>& e, const std::array<int, 2>& f) {
  return e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1];
}

// Per-thread pair lists, concatenated and sorted: the same result whatever the thread count. The
// lists are emptied for the next query, keeping their memory.
template <typename Pair>
void gather(tbb::enumerable_thread_specific<std::vector<Pair>>& local, std::vector<Pair>& out) {
  out.clear();
  for (auto& part : local) {
    out.insert(out.end(), part.begin(), part.end());
    part.clear();
  }
  std::sort(out.begin(), out.end());
}

}  // namespace

CollisionPairs::CollisionPairs(std::vector<std::array<int, 3>> triangles, std::size_t vertexCount)
    : triangles_(std::move(triangles)), vertexCount_(vertexCount) {
  std::set<std::pair<int, int>> edges;
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = triangles_[t][k], b = triangles_[t][(k + 1) % 3];
      if (a < 0 || b < 0 || static_cast<std::size_t>(a) >= vertexCount || static_cast<std::size_t>(b) >= vertexCount)
        throw std::invalid_argument("collision pairs: triangle " + std::to_string(t) + " names a vertex out of range");
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  edges_.reserve(edges.size());
  for (const auto& [a, b] : edges) edges_.push_back({a, b});
}

void CollisionPairs::find(const std::vector<Vec3>& start, const std::vector<Vec3>& end, double margin,
                          std::vector<PointTrianglePair>& pointTriangle, std::vector<EdgeEdgePair>& edgeEdge,
                          const std::vector<char>* moved) {
  if (start.size() != vertexCount_ || end.size() != vertexCount_)
    throw std::invalid_argument("collision pairs: the positions do not match the mesh's vertex count");
  vertexBoxes_.resize(vertexCount_);
  parallelFor(0, vertexCount_, [&](std::size_t v) {
    numerics::Aabb box;
    box.grow(start[v]);
    box.grow(end[v]);
    box.inflate(margin);
    vertexBoxes_[v] = box;
  });
  triangleBoxes_.resize(triangles_.size());
  parallelFor(0, triangles_.size(), [&](std::size_t t) {
    numerics::Aabb box;
    for (const int v : triangles_[t]) box.grow(vertexBoxes_[static_cast<std::size_t>(v)]);
    triangleBoxes_[t] = box;
  });
  edgeBoxes_.resize(edges_.size());
  parallelFor(0, edges_.size(), [&](std::size_t e) {
    numerics::Aabb box = vertexBoxes_[static_cast<std::size_t>(edges_[e][0])];
    box.grow(vertexBoxes_[static_cast<std::size_t>(edges_[e][1])]);
    edgeBoxes_[e] = box;
  });
  if (queries_ % kQueriesPerRebuild == 0 || triangleTree_.empty()) {
    triangleTree_ = numerics::Bvh(triangleBoxes_);
    edgeTree_ = numerics::Bvh(edgeBoxes_);
  } else {
    triangleTree_.refit(triangleBoxes_);
    edgeTree_.refit(edgeBoxes_);
  }
  ++queries_;
  const auto isMoved = [&](int v) { return moved == nullptr || (*moved)[static_cast<std::size_t>(v)] != 0; };

  parallelFor(
      0, vertexCount_,
      [&](std::size_t v) {
        auto& out = localPointTriangle_.local();
        const int point = static_cast<int>(v);
        triangleTree_.forEachOverlap(vertexBoxes_[v], [&](int t) {
          const auto& tri = triangles_[static_cast<std::size_t>(t)];
          if (tri[0] == point || tri[1] == point || tri[2] == point) return;
          if (!isMoved(point) && !isMoved(tri[0]) && !isMoved(tri[1]) && !isMoved(tri[2])) return;
          out.push_back({point, t});
        });
      },
      256);
  gather(localPointTriangle_, pointTriangle);

  parallelFor(
      0, edges_.size(),
      [&](std::size_t e) {
        auto& out = localEdgeEdge_.local();
        const auto& edge = edges_[e];
        edgeTree_.forEachOverlap(edgeBoxes_[e], [&](int f) {
          if (f <= static_cast<int>(e)) return;  // each pair once
          const auto& other = edges_[static_cast<std::size_t>(f)];
          if (sharesVertex(edge, other)) return;
          if (!isMoved(edge[0]) && !isMoved(edge[1]) && !isMoved(other[0]) && !isMoved(other[1])) return;
          out.push_back({static_cast<int>(e), f});
        });
      },
      256);
  gather(localEdgeEdge_, edgeEdge);
}

}  // namespace msim::solids
