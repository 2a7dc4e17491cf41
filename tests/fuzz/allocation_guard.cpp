#include "allocation_guard.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace msim::fuzz {

namespace {

std::atomic<std::size_t> refused{0};
std::atomic<std::size_t> largest{0};

void* allocate(std::size_t size, std::size_t alignment) {
  if (size > kHugeAllocation) {
    refused.fetch_add(1);
    std::size_t seen = largest.load();
    while (size > seen && !largest.compare_exchange_weak(seen, size)) {
    }
    return nullptr;
  }
  if (size == 0) size = 1;
  if (alignment <= alignof(std::max_align_t)) return std::malloc(size);
  return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
}

void* allocateOrThrow(std::size_t size, std::size_t alignment) {
  if (void* p = allocate(size, alignment)) return p;
  throw std::bad_alloc();
}

}  // namespace

std::size_t hugeAllocationCount() { return refused.load(); }
std::size_t largestHugeAllocation() { return largest.load(); }

}  // namespace msim::fuzz

// The replaceable global allocation functions ([new.delete]), all routed through allocate().
void* operator new(std::size_t size) { return msim::fuzz::allocateOrThrow(size, 0); }
void* operator new[](std::size_t size) { return msim::fuzz::allocateOrThrow(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) {
  return msim::fuzz::allocateOrThrow(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a) {
  return msim::fuzz::allocateOrThrow(size, static_cast<std::size_t>(a));
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return msim::fuzz::allocate(size, 0); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return msim::fuzz::allocate(size, 0); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return msim::fuzz::allocate(size, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  return msim::fuzz::allocate(size, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
