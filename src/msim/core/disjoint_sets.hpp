#pragma once
// Disjoint sets of the integers [0, n) under union (union-find, union by size: the trees stay
// shallow without path compression, so root() is const and may run on many threads at once).
// Cloth uses it for rigid impact zones (collisions join particles) and for the groups of pieces
// that may meet within a step (collision_pairs.cpp).
#include <cstddef>
#include <numeric>
#include <utility>
#include <vector>

namespace msim {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t count) : parent_(count), size_(count, 1) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }

  std::size_t size() const { return parent_.size(); }

  // The representative of i's set.
  int root(int i) const {
    while (parent_[static_cast<std::size_t>(i)] != i) i = parent_[static_cast<std::size_t>(i)];
    return i;
  }

  // Joins the sets of a and b; false when they were one already.
  bool join(int a, int b) {
    a = root(a), b = root(b);
    if (a == b) return false;
    if (size_[static_cast<std::size_t>(a)] < size_[static_cast<std::size_t>(b)]) std::swap(a, b);
    parent_[static_cast<std::size_t>(b)] = a;
    size_[static_cast<std::size_t>(a)] += size_[static_cast<std::size_t>(b)];
    return true;
  }

 private:
  std::vector<int> parent_;
  std::vector<int> size_;  // of the tree under each root
};

}  // namespace msim
