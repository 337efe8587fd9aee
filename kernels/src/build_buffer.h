// Scratch memory for a BVH build (private to kernels/src): n elements,
// allocated but neither initialised nor touched, in huge-page-backed memory
// (raybench/bvh/huge_pages.h).
//
// Why: a builder needs room for 2n - 1 nodes and uses about n / 2; a
// std::vector of that size writes all of it first, most of it for nodes
// never used (measured: docs/notes/kernels-builders.md).
#pragma once

#include <cstddef>
#include <type_traits>

#include "raybench/bvh/huge_pages.h"

namespace raybench::bvh2_build {

template <typename T>
class BuildBuffer {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                "elements are placed with std::construct_at and never destroyed");

 public:
  explicit BuildBuffer(std::size_t n)
      : data_(n == 0 ? nullptr : static_cast<T*>(allocate_huge_pages(n * sizeof(T), alignof(T)))), size_(n) {}
  ~BuildBuffer() {
    if (data_ != nullptr) free_huge_pages(data_, size_ * sizeof(T), alignof(T));
  }
  BuildBuffer(const BuildBuffer&) = delete;
  BuildBuffer& operator=(const BuildBuffer&) = delete;

  // Element i, which must have been placed (std::construct_at) before it is read.
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  T* data_;
  std::size_t size_;
};

}  // namespace raybench::bvh2_build
