#pragma once
// The broad phase of cloth collisions (Selle ch. 6.2 step A and 6.3 step C.2): candidate
// point-triangle and edge-edge pairs of one triangle mesh whose boxes overlap, found with
// bounding-volume trees over the triangles' and the edges' boxes. A primitive's box spans its
// vertices at the start and at the end of a motion, grown by a margin: for a mesh at rest
// (start = end) the pairs within the margin (repulsions, step A), for a moving one the pairs
// that may meet during the motion (continuous collision detection, step C). Distances are the
// same in every frame that moves uniformly, so the boxes may be judged in any such frame, and the
// tighter the frame follows the primitives, the fewer boxes overlap: the mesh's pieces (its
// connected parts: leaves, garments) whose boxes over the whole motion overlap form groups, the
// trees find the overlaps within each group in the frame that moves with the group's mean
// displacement (a leaf tumbling through the air is judged in its own frame, not swept along its
// path), and primitives of different groups cannot meet. Each leaf pair is then tested again in
// the frame that moves with its own mean displacement (ch. 6.3, step C.2). The pruning is loose on
// purpose (ch. 6.2): the narrow phase decides. Pairs that share a vertex are never reported
// (a triangle's own vertices, edges meeting at a vertex).
#include <array>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/numerics/bvh.hpp"
#include "msim/solids/particle_split.hpp"

namespace msim::solids {

struct PointTrianglePair {
  int point = 0;     // vertex index
  int triangle = 0;  // triangle index
  bool operator<(const PointTrianglePair& o) const { return point != o.point ? point < o.point : triangle < o.triangle; }
  bool operator==(const PointTrianglePair& o) const = default;
};

struct EdgeEdgePair {
  int first = 0, second = 0;  // edge indices, first < second
  bool operator<(const EdgeEdgePair& o) const { return first != o.first ? first < o.first : second < o.second; }
  bool operator==(const EdgeEdgePair& o) const = default;
};

class CollisionPairs {
 public:
  // The mesh's triangles over `vertexCount` vertices; its edges are derived (each once).
  CollisionPairs(std::vector<std::array<int, 3>> triangles, std::size_t vertexCount);

  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  const std::vector<std::array<int, 2>>& edges() const { return edges_; }
  // Split among processes (particle_split.hpp): whether a pair is this process's to look for and
  // examine, as the owner of its point or of its first edge's first vertex.
  static bool isOwnPair(const ParticleSplit& split, const PointTrianglePair& p) { return split.owns(p.point); }
  bool isOwnPair(const ParticleSplit& split, const EdgeEdgePair& p) const {
    return ownsEdge(split, edges_[static_cast<std::size_t>(p.first)]);
  }

  // Pairs whose boxes over `start` and `end` (the same vector for a mesh at rest), each grown by
  // `margin`, overlap; by point (edge), then in the trees' order: the same whatever the thread count. `moved`, when
  // given, keeps only pairs with at least one vertex flagged (the later passes of step C.5). With a
  // split among processes (particle_split.hpp; collective), each process queries its own points
  // and the edges whose first vertex it owns, and every process ends with all the pairs, in the
  // same order as one process alone.
  void find(const std::vector<Vec3>& start, const std::vector<Vec3>& end, double margin,
            std::vector<PointTrianglePair>& pointTriangle, std::vector<EdgeEdgePair>& edgeEdge,
            const std::vector<char>* moved = nullptr, const ParticleSplit* split = nullptr);

 private:
  // An edge's pairs are looked for by the owner of its first vertex.
  static bool ownsEdge(const ParticleSplit& split, const std::array<int, 2>& edge) { return split.owns(edge[0]); }
  // The vertices' boxes in the frame of their group's mean displacement, and the groups.
  void groupPieces(const std::vector<Vec3>& start, const std::vector<Vec3>& end, double margin);

  std::vector<std::array<int, 3>> triangles_;
  std::vector<std::array<int, 2>> edges_;
  std::size_t vertexCount_;
  std::vector<int> piece_;  // per vertex, its piece (connected part of the mesh), 0 .. pieceCount_ - 1
  int pieceCount_ = 0;
  std::vector<int> group_;  // per vertex, its group in the last find
  int groups_ = 0;
  std::vector<numerics::Aabb> pieceBoxes_;
  std::vector<Vec3> groupShift_;
  std::vector<numerics::Aabb> vertexBoxes_, triangleBoxes_, edgeBoxes_;
  numerics::Bvh triangleTree_, edgeTree_;
  long queries_ = 0;
  std::vector<std::vector<PointTrianglePair>> pointTriangleChunks_;  // per chunk of queries, joined in order
  std::vector<std::vector<EdgeEdgePair>> edgeEdgeChunks_;
};

}  // namespace msim::solids
