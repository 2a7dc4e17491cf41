#pragma once
// Bounding volume hierarchy over axis-aligned boxes: for the rays the renderer traces against
// opaque primitives (render/surfaces.hpp), and for the boxes cloth collisions look for near
// primitives with (solids/collision). Built by the binned surface area heuristic; a moving mesh
// refits the boxes of the same tree (its topology kept, as Selle ch. 6.2 rebuilds only the
// boxes); a query walks it with a fixed stack, so it allocates nothing.
#include <limits>
#include <utility>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::numerics {

struct Aabb {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());

  void grow(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void grow(const Aabb& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  Vec3 centre() const { return 0.5 * (lo + hi); }
  bool overlaps(const Aabb& b) const { return (lo.array() <= b.hi.array()).all() && (b.lo.array() <= hi.array()).all(); }
  void inflate(double margin) {
    lo.array() -= margin;
    hi.array() += margin;
  }
  double halfArea() const {  // half the surface area: the SAH only compares areas
    const Vec3 e = (hi - lo).cwiseMax(0.0);
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
  }
};

class Bvh {
 public:
  Bvh() = default;
  // One box per primitive; primitive i is reported to queries as i.
  explicit Bvh(const std::vector<Aabb>& boxes);

  bool empty() const { return nodes_.empty(); }
  // New boxes for the same primitives (as many as the tree was built with): the nodes' boxes are
  // recomputed bottom up, the tree kept. Cheaper than a rebuild when the primitives move a little.
  void refit(const std::vector<Aabb>& boxes);

  // Calls f(primitive) for every primitive whose box overlaps `query`.
  template <typename F>
  void forEachOverlap(const Aabb& query, F&& f) const {
    if (nodes_.empty()) return;
    int stack[kMaxDepth + 2];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
      if (!node.box.overlaps(query)) continue;
      if (node.count > 0) {
        for (int k = node.first; k < node.first + node.count; ++k) {
          const int p = primitives_[static_cast<std::size_t>(k)];
          if (boxes_[static_cast<std::size_t>(p)].overlaps(query)) f(p);
        }
        continue;
      }
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
  }

  // Calls hit(primitive, tMax) for the primitives whose boxes the ray origin + t dir meets for t in
  // [0, tMax], near subtrees first; hit returns true when the primitive was hit before tMax (and
  // lowered tMax to the hit). With AnyHit the walk stops at the first hit (shadow rays).
  template <bool AnyHit, typename F>
  bool traverse(const Vec3& origin, const Vec3& dir, double& tMax, F&& hit) const {
    if (nodes_.empty()) return false;
    const Vec3 inv(1.0 / dir[0], 1.0 / dir[1], 1.0 / dir[2]);  // +-inf for zero components is fine
    int stack[kMaxDepth + 2];
    int top = 0;
    stack[top++] = 0;
    bool found = false;
    while (top > 0) {
      const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
      // A miss is +infinity, which an unbounded tMax would not cull: boxes are finite, so a box
      // the ray enters has a finite entry.
      if (entry(node.box, origin, inv, tMax) == kMiss) continue;
      if (node.count > 0) {
        for (int k = node.first; k < node.first + node.count; ++k)
          if (hit(primitives_[static_cast<std::size_t>(k)], tMax)) {
            found = true;
            if constexpr (AnyHit) return true;
          }
        continue;
      }
      const double nearL = entry(nodes_[static_cast<std::size_t>(node.first)].box, origin, inv, tMax);
      const double nearR = entry(nodes_[static_cast<std::size_t>(node.first) + 1].box, origin, inv, tMax);
      // Push the far child first so the near one is walked first and shrinks tMax for the other.
      const bool leftFirst = nearL <= nearR;
      stack[top++] = leftFirst ? node.first + 1 : node.first;
      stack[top++] = leftFirst ? node.first : node.first + 1;
    }
    return found;
  }

 private:
  static constexpr int kMaxDepth = 60;  // deeper nodes become leaves, which bounds the stack
  static constexpr double kMiss = std::numeric_limits<double>::infinity();

  struct Node {
    Aabb box;
    int first = 0;  // leaf: first index into primitives_; inner node: the left child (right = first + 1)
    int count = 0;  // primitives of a leaf; 0 for an inner node
  };

  // Ray parameter where the ray enters the box, +infinity when it misses it within [0, tMax].
  static double entry(const Aabb& b, const Vec3& o, const Vec3& inv, double tMax) {
    double t0 = 0.0, t1 = tMax;
    for (int a = 0; a < 3; ++a) {
      double ta = (b.lo[a] - o[a]) * inv[a], tb = (b.hi[a] - o[a]) * inv[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = ta > t0 ? ta : t0;  // NaN (0 * inf on a box face) leaves the bound unchanged
      t1 = tb < t1 ? tb : t1;
    }
    return t0 <= t1 ? t0 : kMiss;
  }

  void build(int node, int begin, int end, int depth, const std::vector<Aabb>& boxes, std::vector<Vec3>& centres);
  void refitNode(int node, const std::vector<Aabb>& boxes);

  std::vector<Node> nodes_;
  std::vector<int> primitives_;
  std::vector<Aabb> boxes_;  // per primitive, as built or last refitted
};

}  // namespace msim::numerics
