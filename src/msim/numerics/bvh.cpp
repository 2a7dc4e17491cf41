#include "msim/numerics/bvh.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace msim::numerics {

namespace {

constexpr int kBins = 12;      // SAH candidate planes per axis and node
constexpr int kLeafSize = 4;   // nodes this small are not split
constexpr double kCostTraversal = 1.0, kCostPrimitive = 1.0;

}  // namespace

Bvh::Bvh(const std::vector<Aabb>& boxes) : boxes_(boxes) {
  if (boxes.empty()) return;
  const int n = static_cast<int>(boxes.size());
  primitives_.resize(boxes.size());
  std::vector<Vec3> centres(boxes.size());
  for (int i = 0; i < n; ++i) {
    primitives_[static_cast<std::size_t>(i)] = i;
    centres[static_cast<std::size_t>(i)] = boxes[static_cast<std::size_t>(i)].centre();
  }
  nodes_.reserve(2 * boxes.size());
  nodes_.emplace_back();
  build(0, 0, n, 0, boxes, centres);
}

// Splits primitives_[begin, end) at the binned SAH plane (the cheapest of kBins - 1 planes per
// axis across the centroids' bounds), or makes a leaf when no split is cheaper than testing every
// primitive, the centroids coincide, or the depth limit is reached.
void Bvh::build(int node, int begin, int end, int depth, const std::vector<Aabb>& boxes, std::vector<Vec3>& centres) {
  Aabb box, centroidBox;
  for (int k = begin; k < end; ++k) {
    const int p = primitives_[static_cast<std::size_t>(k)];
    box.grow(boxes[static_cast<std::size_t>(p)]);
    centroidBox.grow(centres[static_cast<std::size_t>(p)]);
  }
  nodes_[static_cast<std::size_t>(node)].box = box;
  const int count = end - begin;
  const auto makeLeaf = [&] {
    nodes_[static_cast<std::size_t>(node)].first = begin;
    nodes_[static_cast<std::size_t>(node)].count = count;
  };
  if (count <= kLeafSize || depth >= kMaxDepth) return makeLeaf();

  double bestCost = kCostPrimitive * count;  // a leaf's cost, relative to the node's area
  int bestAxis = -1, bestPlane = 0;
  for (int a = 0; a < 3; ++a) {
    const double lo = centroidBox.lo[a], extent = centroidBox.hi[a] - lo;
    if (!(extent > 0.0)) continue;
    std::array<Aabb, kBins> binBox;
    std::array<int, kBins> binCount{};
    for (int k = begin; k < end; ++k) {
      const int p = primitives_[static_cast<std::size_t>(k)];
      const int bin = std::min(kBins - 1, static_cast<int>(kBins * (centres[static_cast<std::size_t>(p)][a] - lo) / extent));
      binBox[static_cast<std::size_t>(bin)].grow(boxes[static_cast<std::size_t>(p)]);
      ++binCount[static_cast<std::size_t>(bin)];
    }
    // Areas and counts left of every plane (sweep from the left), then the cost sweeping back.
    std::array<double, kBins> leftArea{};
    std::array<int, kBins> leftCount{};
    Aabb acc;
    int accCount = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.grow(binBox[static_cast<std::size_t>(b)]);
      accCount += binCount[static_cast<std::size_t>(b)];
      leftArea[static_cast<std::size_t>(b)] = acc.halfArea();
      leftCount[static_cast<std::size_t>(b)] = accCount;
    }
    acc = Aabb();
    accCount = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(binBox[static_cast<std::size_t>(b)]);
      accCount += binCount[static_cast<std::size_t>(b)];
      const int nl = leftCount[static_cast<std::size_t>(b - 1)];
      if (nl == 0 || accCount == 0) continue;
      const double cost = kCostTraversal + kCostPrimitive *
                                               (leftArea[static_cast<std::size_t>(b - 1)] * nl + acc.halfArea() * accCount) /
                                               std::max(box.halfArea(), 1e-300);
      if (cost < bestCost) {
        bestCost = cost;
        bestAxis = a;
        bestPlane = b;  // bins [0, b) go left
      }
    }
  }
  if (bestAxis < 0) return makeLeaf();

  const double lo = centroidBox.lo[bestAxis], extent = centroidBox.hi[bestAxis] - lo;
  const auto goesLeft = [&](int p) {
    return std::min(kBins - 1, static_cast<int>(kBins * (centres[static_cast<std::size_t>(p)][bestAxis] - lo) / extent)) <
           bestPlane;
  };
  const int mid = static_cast<int>(std::partition(primitives_.begin() + begin, primitives_.begin() + end, goesLeft) -
                                   primitives_.begin());
  const int left = static_cast<int>(nodes_.size());
  nodes_[static_cast<std::size_t>(node)].first = left;
  nodes_[static_cast<std::size_t>(node)].count = 0;
  nodes_.emplace_back();
  nodes_.emplace_back();
  build(left, begin, mid, depth + 1, boxes, centres);
  build(left + 1, mid, end, depth + 1, boxes, centres);
}

void Bvh::refit(const std::vector<Aabb>& boxes) {
  if (boxes.size() != primitives_.size()) throw std::invalid_argument("Bvh::refit: the box count differs from the tree's");
  boxes_ = boxes;
  if (!nodes_.empty()) refitNode(0, boxes);
}

void Bvh::refitNode(int node, const std::vector<Aabb>& boxes) {
  Node& n = nodes_[static_cast<std::size_t>(node)];
  Aabb box;
  if (n.count > 0) {
    for (int k = n.first; k < n.first + n.count; ++k) box.grow(boxes[static_cast<std::size_t>(primitives_[static_cast<std::size_t>(k)])]);
  } else {
    refitNode(n.first, boxes);
    refitNode(n.first + 1, boxes);
    box = nodes_[static_cast<std::size_t>(n.first)].box;
    box.grow(nodes_[static_cast<std::size_t>(n.first) + 1].box);
  }
  nodes_[static_cast<std::size_t>(node)].box = box;
}

}  // namespace msim::numerics
