#pragma once
// A std::allocator that aligns every allocation to a cache line (64 bytes), so that vectorised
// loops over the start of an array never split a vector load across two lines, also after the
// container is copied.
#include <cstddef>
#include <new>
#include <vector>

namespace bendlab {

template <class T, std::size_t Alignment = 64>
struct AlignedAllocator {
  using value_type = T;
  AlignedAllocator() noexcept = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U, Alignment>&) noexcept {}
  template <class U>
  struct rebind {
    using other = AlignedAllocator<U, Alignment>;
  };
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{Alignment}));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t{Alignment}); }
  friend bool operator==(const AlignedAllocator&, const AlignedAllocator&) noexcept { return true; }
  friend bool operator!=(const AlignedAllocator&, const AlignedAllocator&) noexcept { return false; }
};

/// A vector of doubles whose data starts on a cache line.
using AlignedDoubles = std::vector<double, AlignedAllocator<double>>;

}  // namespace bendlab
