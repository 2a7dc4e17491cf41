#pragma once
// Stable parallel counting sort of items 0..n-1 into buckets (slabs of grid rows, cells), the
// first step of every deterministic parallel splat: per-block histograms, an exclusive prefix in
// (bucket, block) order, then a parallel scatter. Items keep their input order within a bucket and
// the result does not depend on the thread count. No allocation once the buffers are warm.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

namespace msim {

class BucketSort {
 public:
  // bucketOf(i) < buckets for every item i. std::length_error for more than 2^32 items.
  template <typename BucketOf>
  void sort(std::size_t n, std::size_t buckets, BucketOf&& bucketOf);

  std::size_t buckets() const { return begin_.empty() ? 0 : begin_.size() - 1; }
  // Items of bucket b: order()[begin(b), begin(b + 1)).
  std::size_t begin(std::size_t b) const { return begin_[b]; }
  std::span<const std::uint32_t> order() const { return order_; }

 private:
  static constexpr std::size_t kBlock = 1 << 16;  // items per histogram block
  std::vector<std::uint32_t> bucketOf_, order_;
  std::vector<std::size_t> begin_, cursor_;  // cursor_: [block][bucket] counts, then write positions
};

template <typename BucketOf>
void BucketSort::sort(std::size_t n, std::size_t buckets, BucketOf&& bucketOf) {
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("BucketSort: more than 2^32 items (" + std::to_string(n) + ")");
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  bucketOf_.resize(n);
  order_.resize(n);
  cursor_.assign(blocks * buckets, 0);
  begin_.assign(buckets + 1, 0);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    std::size_t* count = &cursor_[b * buckets];
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) {
      bucketOf_[i] = static_cast<std::uint32_t>(bucketOf(i));
      ++count[bucketOf_[i]];
    }
  });
  std::size_t running = 0;
  for (std::size_t s = 0; s < buckets; ++s) {
    begin_[s] = running;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t count = cursor_[b * buckets + s];
      cursor_[b * buckets + s] = running;
      running += count;
    }
  }
  begin_[buckets] = running;
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t b) {
    std::size_t* cursor = &cursor_[b * buckets];
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) order_[cursor[bucketOf_[i]]++] = static_cast<std::uint32_t>(i);
  });
}

}  // namespace msim
