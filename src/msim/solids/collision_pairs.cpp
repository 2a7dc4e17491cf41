#include "msim/solids/collision_pairs.hpp"

#include <algorithm>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>

#include "msim/core/disjoint_sets.hpp"
#include "msim/core/parallel.hpp"

namespace msim::solids {

namespace {

// Refitted trees are rebuilt after this many queries: a crumpling cloth moves its triangles far
// from where the tree's split planes were chosen, and refitted boxes then overlap more and more.
constexpr int kQueriesPerRebuild = 16;

bool sharesVertex(const std::array<int, 2>& e, const std::array<int, 2>& f) {
  return e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1];
}

// Whether two groups of vertices (first `split` of `v`, then the rest), each moving on a straight
// line from start to end, may come within 2 margin of each other, judged in the frame that moves
// with their mean displacement (Selle ch. 6.3, step C.2): a distance is the same in every frame
// moving uniformly, and in this one the boxes of a pair that moves together (a cloth's flap swinging
// as a whole) stay small, where in the frame of the cloth's mean motion they sweep the flap's path.
bool mayMeetInPairFrame(const std::vector<Vec3>& start, const std::vector<Vec3>& end, const std::array<int, 4>& v,
                        int split, double margin) {
  Vec3 mean = Vec3::Zero();
  for (const int i : v) mean += end[static_cast<std::size_t>(i)] - start[static_cast<std::size_t>(i)];
  mean /= 4.0;
  numerics::Aabb a, b;
  for (int k = 0; k < 4; ++k) {
    const auto i = static_cast<std::size_t>(v[static_cast<std::size_t>(k)]);
    numerics::Aabb& box = k < split ? a : b;
    box.grow(start[i]);
    box.grow(end[i] - mean);
  }
  a.inflate(margin);
  b.inflate(margin);
  return a.overlaps(b);
}

// Queries per chunk: each chunk's finds go to its own list, and the lists are joined in the
// chunks' order, so the pairs come out in the same order whatever the thread count (without the
// cost of sorting millions of them). The lists keep their memory for the next query.
constexpr std::size_t kChunk = 256;

template <typename Pair, typename Query>
void findInChunks(std::size_t count, std::vector<std::vector<Pair>>& chunks, std::vector<Pair>& out, Query&& query) {
  const std::size_t chunkCount = (count + kChunk - 1) / kChunk;
  if (chunks.size() < chunkCount) chunks.resize(chunkCount);
  parallelFor(0, chunkCount, [&](std::size_t c) {
    std::vector<Pair>& found = chunks[c];
    found.clear();
    for (std::size_t i = c * kChunk; i < std::min(count, (c + 1) * kChunk); ++i) query(i, found);
  }, 1);
  std::size_t total = 0;
  for (std::size_t c = 0; c < chunkCount; ++c) total += chunks[c].size();
  out.clear();
  out.reserve(total);
  for (std::size_t c = 0; c < chunkCount; ++c) out.insert(out.end(), chunks[c].begin(), chunks[c].end());
}

// Every process's pairs, each process's in the order of its queries (by point or first edge, each
// queried by one process), joined on every process and put in the order of the queries: the
// pairs one process alone finds.
template <typename Pair, typename Fields>
void joinPairs(const ParticleSplit& split, std::vector<Pair>& pairs, Fields&& fields) {
  std::vector<double> rows;
  rows.reserve(2 * pairs.size());
  for (const Pair& p : pairs) {
    const std::array<int, 2> f = fields(p);
    rows.insert(rows.end(), {double(f[0]), double(f[1])});
  }
  split.gatherRows(rows, 2);
  pairs.resize(rows.size() / 2);
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k] = Pair{static_cast<int>(rows[2 * k]), static_cast<int>(rows[2 * k + 1])};
  std::stable_sort(pairs.begin(), pairs.end(), [&](const Pair& a, const Pair& b) { return fields(a)[0] < fields(b)[0]; });
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
  DisjointSets pieces(vertexCount);
  for (const auto& [a, b] : edges_) pieces.join(a, b);
  std::vector<int> pieceOfRoot(vertexCount, -1);
  piece_.resize(vertexCount);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    int& piece = pieceOfRoot[static_cast<std::size_t>(pieces.root(static_cast<int>(v)))];
    if (piece < 0) piece = pieceCount_++;
    piece_[v] = piece;
  }
}

void CollisionPairs::groupPieces(const std::vector<Vec3>& start, const std::vector<Vec3>& end, double margin) {
  // Each piece's box over the whole motion; pieces whose boxes overlap join a group (sweep and
  // prune along x).
  pieceBoxes_.assign(static_cast<std::size_t>(pieceCount_), numerics::Aabb{});
  for (std::size_t v = 0; v < vertexCount_; ++v) {
    numerics::Aabb& box = pieceBoxes_[static_cast<std::size_t>(piece_[v])];
    box.grow(start[v]);
    box.grow(end[v]);
  }
  for (numerics::Aabb& box : pieceBoxes_) box.inflate(margin);
  std::vector<int> order(static_cast<std::size_t>(pieceCount_));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return pieceBoxes_[static_cast<std::size_t>(a)].lo.x() < pieceBoxes_[static_cast<std::size_t>(b)].lo.x();
  });
  DisjointSets groups(static_cast<std::size_t>(pieceCount_));
  for (std::size_t i = 0; i < order.size(); ++i) {
    const numerics::Aabb& box = pieceBoxes_[static_cast<std::size_t>(order[i])];
    for (std::size_t j = i + 1; j < order.size(); ++j) {
      const numerics::Aabb& other = pieceBoxes_[static_cast<std::size_t>(order[j])];
      if (other.lo.x() > box.hi.x()) break;
      if (box.overlaps(other)) groups.join(order[i], order[j]);
    }
  }
  // Each group's mean displacement, and the vertices' boxes in its frame.
  groupShift_.assign(static_cast<std::size_t>(pieceCount_), Vec3::Zero());
  std::vector<int> count(static_cast<std::size_t>(pieceCount_), 0);
  group_.resize(vertexCount_);
  for (std::size_t v = 0; v < vertexCount_; ++v) {
    const int group = groups.root(piece_[v]);
    group_[v] = group;
    groupShift_[static_cast<std::size_t>(group)] += end[v] - start[v];
    ++count[static_cast<std::size_t>(group)];
  }
  groups_ = 0;
  for (std::size_t g = 0; g < groupShift_.size(); ++g)
    if (count[g] > 0) {
      groupShift_[g] /= static_cast<double>(count[g]);
      ++groups_;
    }
  vertexBoxes_.resize(vertexCount_);
  parallelFor(0, vertexCount_, [&](std::size_t v) {
    numerics::Aabb box;
    box.grow(start[v]);
    box.grow(end[v] - groupShift_[static_cast<std::size_t>(group_[v])]);
    box.inflate(margin);
    vertexBoxes_[v] = box;
  });
}

void CollisionPairs::find(const std::vector<Vec3>& start, const std::vector<Vec3>& end, double margin,
                          std::vector<PointTrianglePair>& pointTriangle, std::vector<EdgeEdgePair>& edgeEdge,
                          const std::vector<char>* moved, const ParticleSplit* split) {
  if (start.size() != vertexCount_ || end.size() != vertexCount_)
    throw std::invalid_argument("collision pairs: the positions do not match the mesh's vertex count");
  groupPieces(start, end, margin);
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

  findInChunks(vertexCount_, pointTriangleChunks_, pointTriangle, [&](std::size_t v, std::vector<PointTrianglePair>& out) {
        const int point = static_cast<int>(v);
        if (split && !split->owns(point)) return;
        triangleTree_.forEachOverlap(vertexBoxes_[v], [&](int t) {
          const auto& tri = triangles_[static_cast<std::size_t>(t)];
          if (tri[0] == point || tri[1] == point || tri[2] == point) return;
          if (groups_ > 1 && group_[v] != group_[static_cast<std::size_t>(tri[0])]) return;  // boxes in different frames
          if (!isMoved(point) && !isMoved(tri[0]) && !isMoved(tri[1]) && !isMoved(tri[2])) return;
          if (!mayMeetInPairFrame(start, end, {point, tri[0], tri[1], tri[2]}, 1, margin)) return;
          out.push_back({point, t});
        });
      });

  findInChunks(edges_.size(), edgeEdgeChunks_, edgeEdge, [&](std::size_t e, std::vector<EdgeEdgePair>& out) {
        const auto& edge = edges_[e];
        if (split && !ownsEdge(*split, edge)) return;
        edgeTree_.forEachOverlap(edgeBoxes_[e], [&](int f) {
          if (f <= static_cast<int>(e)) return;  // each pair once
          const auto& other = edges_[static_cast<std::size_t>(f)];
          if (sharesVertex(edge, other)) return;
          if (groups_ > 1 && group_[static_cast<std::size_t>(edge[0])] != group_[static_cast<std::size_t>(other[0])]) return;
          if (!isMoved(edge[0]) && !isMoved(edge[1]) && !isMoved(other[0]) && !isMoved(other[1])) return;
          if (!mayMeetInPairFrame(start, end, {edge[0], edge[1], other[0], other[1]}, 2, margin)) return;
          out.push_back({static_cast<int>(e), f});
        });
      });
  if (split) {
    joinPairs(*split, pointTriangle, [](const PointTrianglePair& p) { return std::array<int, 2>{p.point, p.triangle}; });
    joinPairs(*split, edgeEdge, [](const EdgeEdgePair& p) { return std::array<int, 2>{p.first, p.second}; });
  }
}

}  // namespace msim::solids
